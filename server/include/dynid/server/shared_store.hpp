#pragma once
// SharedStore: the one Store of the process (store.hpp: one Store per file and process, one
// thread at a time), shared by the workers through a mutex.
//
// Storing is fsync-bound and serial anyway; the CPU-heavy folding happens outside the lock,
// so workers hold it only for a store call (and read replays in bounded batches).
#include <mutex>
#include <utility>

#include "dynid/store/store.hpp"

namespace dynid::server {

class SharedStore {
 public:
  SharedStore(const std::string& path, store::StoreOptions options)
      : store_(path, std::move(options)) {}

  /// Runs f(store) under the lock and returns its result.
  template <typename F>
  auto with(F&& f) {
    std::lock_guard lock(mutex_);
    return std::forward<F>(f)(store_);
  }

 private:
  std::mutex mutex_;
  store::Store store_;
};

}  // namespace dynid::server
