#pragma once
// Committer: the store's writing thread. Workers hand it batches of writes and go on folding;
// it runs every batch queued at that moment in one transaction (Store::batch), so the batches
// of all workers become durable with one fsync, then reports each batch's outcome to its
// submitter.
//
// Why a thread: with the workers committing themselves, each worker waited for its own fsync
// (2-5 ms here) before folding on, and for the other worker's, which held the store meanwhile.
// Now a worker folds batch k while batch k+1 is being committed, and one fsync covers both
// workers' batches (docs/BENCHMARKS.md, "Load").
//
// Contract:
// - submit(writes, done): `writes` runs later on the committer's thread, inside a transaction
//   shared with the other batches taken with it, under the SharedStore's lock. Batches are run
//   and committed in the order they were submitted. Each write inside is a savepoint
//   (Store::batch): one that throws InputError is rolled back alone; `writes` must catch it.
// - done(committed, error) is called on the committer's thread after the commit: committed =
//   true means every write `writes` made is durable (only then may its chunks be
//   acknowledged). When the transaction fails (StoreError: a full disk, an I/O error) or
//   `writes` throws anything else, nothing of any batch taken with it is stored, and every one
//   of them gets committed = false with the reason. `done` must not block on a worker (it may
//   be waiting for this very outcome): it records the outcome and wakes its worker.
// - stop() commits what is queued, then joins; submit() after stop() reports committed =
//   false ("store closed") at once. Idempotent; the destructor calls it.
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "dynid/server/shared_store.hpp"

namespace dynid::server {

class Committer {
 public:
  using Writes = std::function<void(store::Store&)>;
  using Done = std::function<void(bool committed, const std::string& error)>;

  explicit Committer(SharedStore& store);
  Committer(const Committer&) = delete;
  Committer& operator=(const Committer&) = delete;
  ~Committer();

  void submit(Writes writes, Done done);
  void stop();

 private:
  struct Batch {
    Writes writes;
    Done done;
  };
  void run();
  /// One transaction for all of `batches`; the reason it failed, nullopt when committed.
  std::optional<std::string> commit(std::deque<Batch>& batches);

  SharedStore& store_;
  std::mutex mutex_;
  std::condition_variable queued_;
  std::deque<Batch> queue_;
  bool stopping_ = false;
  std::thread thread_;  // last: started once everything above exists
};

}  // namespace dynid::server
