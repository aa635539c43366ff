// Store::batch (group commit): the writes of a batch commit together; a refused write inside
// it is rolled back alone; a batch that throws leaves nothing; a batch cannot nest.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include "dynid/error.hpp"
#include "store_test_support.hpp"

namespace dynid::store::test {
namespace {

TEST(StoreBatch, WritesCommitTogetherAndARefusedOneIsRolledBackAlone) {
  TempDir dir;
  const std::string path = dir.file("batch.db");
  {
    Store store(path);
    store.add_run(announcement("car", "r1"));
    store.batch([](Store& s) {
      EXPECT_EQ(s.store_chunk(chunk("car", "r1", 0)).status, ChunkStatus::stored);
      EXPECT_EQ(s.store_chunk(chunk("car", "r1", 1)).status, ChunkStatus::stored);
      // A conflicting copy of #0 is refused with a reason; #1's bytes again are a duplicate.
      EXPECT_EQ(s.store_chunk(chunk("car", "r1", 0, 10, 1)).status, ChunkStatus::conflict);
      EXPECT_EQ(s.store_chunk(chunk("car", "r1", 1)).status, ChunkStatus::duplicate);
      // A chunk of an unknown run throws InputError: its savepoint alone is rolled back.
      EXPECT_THROW(s.store_chunk(chunk("car", "nope", 0)), InputError);
      EXPECT_EQ(s.store_chunk(chunk("car", "r1", 2)).status, ChunkStatus::stored);
      s.mark_folded({"car", "r1"}, 1);
      EXPECT_THROW(s.mark_folded({"car", "r1"}, 0), InputError);  // would fold twice
      s.save_checkpoint({"car", "r1"}, 2, "state-2");
    });
  }
  Store reopened(path);
  EXPECT_EQ(reopened.highest_contiguous({"car", "r1"}), 2u);
  const auto checkpoint = reopened.latest_checkpoint({"car", "r1"});
  ASSERT_TRUE(checkpoint);
  EXPECT_EQ(checkpoint->folded_through, 2u);
  EXPECT_EQ(checkpoint->state, "state-2");
  auto stream = reopened.chunks({"car", "r1"}, 0, 2);
  for (std::uint64_t k = 0; k <= 2; ++k) {
    const auto stored = stream.next();
    ASSERT_TRUE(stored);
    EXPECT_TRUE(same(*stored, chunk("car", "r1", k)));
  }
}

TEST(StoreBatch, ABatchThatThrowsLeavesNothing) {
  TempDir dir;
  Store store(dir.file("batch.db"));
  store.add_run(announcement("car", "r1"));
  EXPECT_THROW(store.batch([](Store& s) {
    s.store_chunk(chunk("car", "r1", 0));
    s.store_chunk(chunk("car", "r1", 1));
    throw std::runtime_error("the caller gives up");
  }),
               std::runtime_error);
  EXPECT_FALSE(store.highest_contiguous({"car", "r1"}));
  EXPECT_EQ(store.store_chunk(chunk("car", "r1", 0)).status, ChunkStatus::stored);  // usable
}

// The writer's commits do not copy the log back into the database file (they would wait for
// it): a thread of the store does, on its own connection. 40 commits of ~25 KB are ~400 log
// frames (chunk pages, index, ledger), below SQLite's own 1000-frame autocheckpoint, above the
// thread's 256: they reach the database file while the store is open (without the thread the
// file stays at its schema's few pages: checked by disabling it).
TEST(StoreBatch, TheLogIsCopiedIntoTheFileWhileTheStoreIsOpen) {
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

TEST(StoreBatch, CannotNest) {
  TempDir dir;
  Store store(dir.file("batch.db"));
  store.add_run(announcement("car", "r1"));
  EXPECT_THROW(store.batch([](Store& s) { s.batch([](Store&) {}); }), InputError);
  EXPECT_FALSE(store.highest_contiguous({"car", "r1"}));
}

}  // namespace
}  // namespace dynid::store::test
