// The contract suite (store_contract.hpp) on SQLite files in a temporary folder, and what only
// the SQLite backend does: the thread that copies its write-ahead log back into the file.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "store_contract.hpp"

namespace dynid::store::test {
namespace {

std::string sqlite_file(const TempDir& dir) {
  return dir.file("store.db");
}

const Engine kSqlite{"sqlite", &sqlite_file};

DYNID_INSTANTIATE_STORE_CONTRACT(Sqlite, kSqlite);

// The writer's commits do not copy the log back into the database file (they would wait for
// it): a thread of the store does, on its own connection. 40 commits of ~25 KB are ~400 log
// frames (chunk pages, index, ledger), below SQLite's own 1000-frame autocheckpoint, above the
// thread's 256: they reach the database file while the store is open (without the thread the
// file stays at its schema's few pages: checked by disabling it).
TEST(StoreSqlite, TheLogIsCopiedIntoTheFileWhileTheStoreIsOpen) {
  TempDir dir;
  const std::string path = dir.file("log.db");
  Store store(path);
  store.add_run(announcement("car", "r1"));
  constexpr std::uint64_t kChunks = 40;
  for (std::uint64_t k = 0; k < kChunks; ++k)
    ASSERT_EQ(store.store_chunk(chunk("car", "r1", k, 1000)).status, ChunkStatus::stored);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::filesystem::file_size(path) < 500'000 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_GE(std::filesystem::file_size(path), 500'000u) << "the log was not checkpointed";
  auto stream = store.chunks({"car", "r1"}, 0, kChunks - 1);
  for (std::uint64_t k = 0; k < kChunks; ++k) {
    const auto stored = stream.next();
    ASSERT_TRUE(stored);
    EXPECT_TRUE(same(*stored, chunk("car", "r1", k, 1000)));
  }
}

}  // namespace
}  // namespace dynid::store::test
