#pragma once
// WorkerPool: a fixed set of worker threads, each with its own task queue. The server pins
// every vehicle to one worker (worker_of), so the tasks of one vehicle run one at a time, in
// the order they were posted: chunks of a run are stored and folded in arrival order without
// a lock per run, while other vehicles' runs fold on the other cores.
//
// Contract:
// - post() enqueues; when the worker's queue holds `max_queue` tasks it blocks until there is
//   room (back-pressure to the DDS reader, whose keep-all limits then hold the cars back).
//   post_unbounded() never blocks: for a completion the worker may itself be waiting for
//   (the committer's wake-up), which a full queue must not hold back.
// - A worker takes every task queued at once, runs them in order, then calls tick(worker)
//   once; idle, it calls tick at least every `tick_period`. The server stores the chunks of
//   such a batch in one transaction and publishes throttled estimates there, so a busy worker
//   commits many chunks per fsync and an idle one commits each chunk on its own.
// - A task that throws is logged and dropped; the worker goes on.
// - stop() lets every worker finish the tasks already queued, then joins them. Idempotent;
//   the destructor calls it.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <string_view>
#include <thread>
#include <vector>

namespace dynid::server {

class WorkerPool {
 public:
  using Task = std::function<void()>;
  using Tick = std::function<void(std::size_t worker)>;

  /// Throws std::runtime_error naming the worker when a thread cannot be started (the ones
  /// already started are stopped and joined first).
  WorkerPool(std::size_t workers, std::size_t max_queue, std::chrono::milliseconds tick_period,
             Tick tick);
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  ~WorkerPool();

  std::size_t size() const { return queues_.size(); }
  /// The worker a vehicle is pinned to.
  std::size_t worker_of(std::string_view vehicle) const;
  void post(std::size_t worker, Task task);
  void post_unbounded(std::size_t worker, Task task);
  void stop();

 private:
  struct Queue {
    std::mutex mutex;
    std::condition_variable changed;
    std::deque<Task> tasks;
    bool stopping = false;
  };
  void run(std::size_t worker);
  void enqueue(std::size_t worker, Task task, bool bounded);
  static void run_task(std::size_t worker, const Task& task);  // logs and drops a throw

  std::size_t max_queue_;
  std::chrono::milliseconds tick_period_;
  Tick tick_;
  std::vector<std::unique_ptr<Queue>> queues_;
  std::vector<std::thread> threads_;
};

}  // namespace dynid::server
