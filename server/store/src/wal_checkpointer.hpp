#pragma once
// WalCheckpointer: copies the write-ahead log back into the database file on a thread and a
// connection of its own, so that the writer's commits do not.
//
// Why: SQLite's automatic checkpoint runs inside the COMMIT that crosses its threshold (1000
// pages): that commit then copies ~4 MB into the database file and fsyncs it, while every
// server worker waits for the store. With 1000 vehicles (24 MB/s of chunks) that happened
// several times a second and made the acknowledgement latency's tail (docs/BENCHMARKS.md, Load).
//
// Contract:
// - Constructed on an open WAL-mode Database (the writer's), it installs a WAL hook on that
//   connection, which replaces SQLite's autocheckpoint. After each commit whose log holds at
//   least `wake_pages` pages the thread is woken and runs a PASSIVE checkpoint on its own
//   connection: it never blocks a writer or a reader, and copies only frames that no reader
//   still needs. Once a checkpoint has copied the whole log, the next commit starts the log
//   over from its beginning, so the log stays about one batch long while the thread keeps up.
// - Should the log reach `inline_pages` (the thread fell behind, or its checkpoints fail), the
//   committing connection runs a PASSIVE checkpoint itself, as SQLite's autocheckpoint would:
//   the log stays bounded whatever happens to the thread.
// - Durability is unchanged: a commit is durable when it is in the fsync'd log; a checkpoint
//   (which fsyncs the log before and the database after copying) only moves committed pages.
//   A failed checkpoint (a full disk) loses nothing: the frames stay in the log, the next one
//   retries. It is not reported to any writer (its own write fails on its own if the disk is
//   full), only counted in failures().
// - The destructor removes the hook, stops and joins the thread and closes its connection; it
//   must run before the writer's Database closes (declare the checkpointer after it).
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>

#include "sqlite.hpp"

namespace dynid::store::detail {

class WalCheckpointer {
 public:
  static constexpr int kWakePages = 256;      // 1 MiB of 4 KiB pages: ~40 chunks
  static constexpr int kInlinePages = 16384;  // 64 MiB: the log's bound if the thread lags

  explicit WalCheckpointer(Database& writer, int wake_pages = kWakePages,
                           int inline_pages = kInlinePages);
  ~WalCheckpointer();
  WalCheckpointer(const WalCheckpointer&) = delete;
  WalCheckpointer& operator=(const WalCheckpointer&) = delete;

  /// Checkpoints run by the thread, and those that failed (other than SQLITE_BUSY).
  std::uint64_t completed() const { return completed_.load(); }
  std::uint64_t failures() const { return failures_.load(); }

 private:
  static int on_commit(void* self, ::sqlite3* db, const char* schema, int pages);
  void run();

  Database& writer_;
  int wake_pages_;
  int inline_pages_;
  std::unique_ptr<Database> own_;  // the thread's connection
  std::mutex mutex_;
  std::condition_variable wake_;
  bool due_ = false;
  bool stopping_ = false;
  std::atomic<std::uint64_t> completed_{0};
  std::atomic<std::uint64_t> failures_{0};
  std::thread thread_;  // last: started once everything above exists
};

}  // namespace dynid::store::detail
