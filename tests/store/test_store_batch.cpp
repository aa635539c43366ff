// Store::batch (group commit), on every backend (store_contract.hpp): the writes of a batch
// commit together; a refused write inside it is rolled back alone; a batch that throws leaves
// nothing; a batch cannot nest.
#include <gtest/gtest.h>

#include <stdexcept>

#include "dynid/error.hpp"
#include "store_contract.hpp"

namespace dynid::store::test {
namespace {

TEST_P(StoreBatch, WritesCommitTogetherAndARefusedOneIsRolledBackAlone) {
  {
    Store store = open();
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
  Store reopened = open();
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

TEST_P(StoreBatch, ABatchThatThrowsLeavesNothing) {
  Store store = open();
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

TEST_P(StoreBatch, CannotNest) {
  Store store = open();
  store.add_run(announcement("car", "r1"));
  EXPECT_THROW(store.batch([](Store& s) { s.batch([](Store&) {}); }), InputError);
  EXPECT_FALSE(store.highest_contiguous({"car", "r1"}));
}

}  // namespace
}  // namespace dynid::store::test
