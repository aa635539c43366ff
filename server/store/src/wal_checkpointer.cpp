#include "wal_checkpointer.hpp"

#include <sqlite3.h>

namespace dynid::store::detail {

WalCheckpointer::WalCheckpointer(Database& writer, int wake_pages, int inline_pages)
    : writer_(writer),
      wake_pages_(wake_pages),
      inline_pages_(inline_pages),
      own_(std::make_unique<Database>(writer.path(), false)) {
  // The thread's checkpoints fsync like the writer's commits (see store.hpp, Durability).
  own_->exec("PRAGMA synchronous = FULL", "set synchronous (checkpointer)");
  sqlite3_wal_hook(writer_.handle(), &WalCheckpointer::on_commit, this);
  thread_ = std::thread([this] { run(); });
}

WalCheckpointer::~WalCheckpointer() {
  sqlite3_wal_hook(writer_.handle(), nullptr, nullptr);
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

// Runs in the writer's thread after each commit, with the log's size in pages.
int WalCheckpointer::on_commit(void* self, ::sqlite3* db, const char* schema, int pages) {
  auto& me = *static_cast<WalCheckpointer*>(self);
  if (pages >= me.inline_pages_) {
    sqlite3_wal_checkpoint_v2(db, schema, SQLITE_CHECKPOINT_PASSIVE, nullptr, nullptr);
  } else if (pages >= me.wake_pages_) {
    {
      std::lock_guard lock(me.mutex_);
      me.due_ = true;
    }
    me.wake_.notify_one();
  }
  return SQLITE_OK;  // a checkpoint's outcome is never the commit's
}

void WalCheckpointer::run() {
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return due_ || stopping_; });
      if (stopping_) return;
      due_ = false;
    }
    const int rc = sqlite3_wal_checkpoint_v2(own_->handle(), nullptr, SQLITE_CHECKPOINT_PASSIVE,
                                             nullptr, nullptr);
    if (rc == SQLITE_OK)
      completed_.fetch_add(1);
    else if ((rc & 0xff) != SQLITE_BUSY)  // busy: another checkpoint runs; the next wake retries
      failures_.fetch_add(1);
  }
}

}  // namespace dynid::store::detail
