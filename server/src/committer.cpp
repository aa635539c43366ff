// Committer: one transaction for every batch queued (contract in committer.hpp).
#include "dynid/server/committer.hpp"

namespace dynid::server {

Committer::Committer(SharedStore& store) : store_(store), thread_([this] { run(); }) {}

Committer::~Committer() { stop(); }

void Committer::submit(Writes writes, Done done) {
  {
    std::lock_guard lock(mutex_);
    if (!stopping_) {
      queue_.push_back({std::move(writes), std::move(done)});
      queued_.notify_one();
      return;
    }
  }
  done(false, "store closed (server stopping)");
}

void Committer::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    queued_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
}

void Committer::run() {
  for (;;) {
    std::deque<Batch> batches;
    {
      std::unique_lock lock(mutex_);
      queued_.wait(lock, [&] { return !queue_.empty() || stopping_; });
      if (queue_.empty()) return;  // stopping, and everything submitted is committed
      batches.swap(queue_);        // all of them: one transaction, one fsync
    }
    const auto error = commit(batches);
    for (auto& batch : batches) batch.done(!error, error.value_or(""));
  }
}

std::optional<std::string> Committer::commit(std::deque<Batch>& batches) {
  try {
    store_.with([&](store::Store& s) {
      s.batch([&](store::Store& b) {
        for (auto& batch : batches) batch.writes(b);
      });
    });
    return std::nullopt;
  } catch (const std::exception& e) {  // each submitter reports it for its own batch
    return e.what();
  }
}

}  // namespace dynid::server
