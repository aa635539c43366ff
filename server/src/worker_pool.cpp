#include "dynid/server/worker_pool.hpp"

#include <spdlog/spdlog.h>

#include <stdexcept>
#include <system_error>

#include "dynid/server/shard.hpp"

namespace dynid::server {

WorkerPool::WorkerPool(std::size_t workers, std::size_t max_queue,
                       std::chrono::milliseconds tick_period, Tick tick)
    : max_queue_(std::max<std::size_t>(1, max_queue)),
      tick_period_(tick_period),
      tick_(std::move(tick)) {
  for (std::size_t k = 0; k < std::max<std::size_t>(1, workers); ++k)
    queues_.push_back(std::make_unique<Queue>());
  try {
    for (std::size_t k = 0; k < queues_.size(); ++k) threads_.emplace_back([this, k] { run(k); });
  } catch (const std::system_error& e) {
    // The threads already started must end before they are destroyed (else std::terminate).
    const std::size_t started = threads_.size();
    stop();
    throw std::runtime_error("worker pool: cannot start worker " + std::to_string(started + 1) + " of " +
                             std::to_string(queues_.size()) + ": " + e.what());
  }
}

WorkerPool::~WorkerPool() { stop(); }

std::size_t WorkerPool::worker_of(std::string_view vehicle) const {
  // Another mix than Shard's (fnv1a64 mod N): with the same one, all vehicles of a shard
  // would land on one worker whenever the worker count equals the shard count.
  const std::uint64_t h = fnv1a64(vehicle);
  return static_cast<std::size_t>((h >> 32 ^ h * 0x9e3779b97f4a7c15ULL) % queues_.size());
}

void WorkerPool::post(std::size_t worker, Task task) { enqueue(worker, std::move(task), true); }

void WorkerPool::post_unbounded(std::size_t worker, Task task) {
  enqueue(worker, std::move(task), false);
}

void WorkerPool::enqueue(std::size_t worker, Task task, bool bounded) {
  Queue& q = *queues_.at(worker);
  std::unique_lock lock(q.mutex);
  if (bounded) q.changed.wait(lock, [&] { return q.tasks.size() < max_queue_ || q.stopping; });
  if (q.stopping) return;
  q.tasks.push_back(std::move(task));
  q.changed.notify_all();
}

void WorkerPool::run(std::size_t worker) {
  Queue& q = *queues_[worker];
  for (;;) {
    std::deque<Task> batch;
    {
      std::unique_lock lock(q.mutex);
      q.changed.wait_for(lock, tick_period_, [&] { return !q.tasks.empty() || q.stopping; });
      if (q.tasks.empty() && q.stopping) return;
      batch.swap(q.tasks);  // everything queued: one tick for all (the server's group commit)
      q.changed.notify_all();  // room for blocked post()s
    }
    for (auto& task : batch) run_task(worker, task);
    run_task(worker, [this, worker] {
      if (tick_) tick_(worker);
    });
  }
}

void WorkerPool::run_task(std::size_t worker, const Task& task) {
  try {
    task();
  } catch (const std::exception& e) {
    spdlog::error("worker {}: task failed: {}", worker, e.what());
  }
}

void WorkerPool::stop() {
  for (auto& q : queues_) {
    std::lock_guard lock(q->mutex);
    q->stopping = true;
    q->changed.notify_all();
  }
  for (auto& t : threads_)
    if (t.joinable()) t.join();
  threads_.clear();
}

}  // namespace dynid::server
