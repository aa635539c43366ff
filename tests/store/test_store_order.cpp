// Duplicates, conflicts and out-of-order chunks: what is stored, what the acknowledgement
// (highest contiguous sequence) says, and what is refused.
#include <gtest/gtest.h>

#include "dynid/error.hpp"
#include "dynid/store/store.hpp"
#include "store_contract.hpp"

namespace dynid::store::test {
namespace {

const RunKey kRun{"proto-17", "run-1"};

TEST_P(StoreOrder, DuplicateIsReacknowledgedAndConflictChangesNothing) {
  ASSERT_EQ(put(0).status, ChunkStatus::stored);
  ASSERT_EQ(put(1).status, ChunkStatus::stored);
  const auto duplicate = put(0);
  EXPECT_EQ(duplicate.status, ChunkStatus::duplicate);
  EXPECT_EQ(duplicate.contiguous_through, 1u);

  const auto conflict = put(1, /*variant=*/1);
  EXPECT_EQ(conflict.status, ChunkStatus::conflict);
  EXPECT_NE(conflict.reason.find("proto-17/run-1#1"), std::string::npos) << conflict.reason;
  EXPECT_EQ(stored_count(), 2u);
  auto stream = store_->chunks(kRun, 1, 1);
  EXPECT_TRUE(test::same(*stream.next(), chunk("proto-17", "run-1", 1)));  // the first stays
}

TEST_P(StoreOrder, ChunksAheadOfAGapAreStoredButNotAcknowledgedUntilTheGapCloses) {
  ASSERT_EQ(put(0).status, ChunkStatus::stored);
  for (std::uint64_t s : {3u, 2u, 5u}) {
    const auto result = put(s);
    EXPECT_EQ(result.status, ChunkStatus::stored) << s;
    EXPECT_EQ(result.contiguous_through, 0u) << s;  // 1 is missing
  }
  EXPECT_EQ(put(3).status, ChunkStatus::duplicate);  // a resend of a chunk held ahead
  EXPECT_EQ(put(3, 1).status, ChunkStatus::conflict);
  const auto closing = put(1);
  EXPECT_EQ(closing.status, ChunkStatus::stored);
  EXPECT_EQ(closing.contiguous_through, 3u);  // jumps over 2 and 3; 4 still missing
  EXPECT_EQ(put(4).contiguous_through, 5u);
  EXPECT_EQ(store_->highest_contiguous(kRun), 5u);
  auto stream = store_->chunks(kRun, 0, 5);
  for (std::uint64_t s = 0; s <= 5; ++s) EXPECT_EQ(stream.next()->sequence, s);
}

TEST_P(StoreOrder, ChunksBeyondTheWindowAreRefusedAndNotStored) {
  ASSERT_EQ(put(0).status, ChunkStatus::stored);
  // Window 8 after contiguous 0: sequences 1..8 may be stored, 9 may not.
  EXPECT_EQ(put(8).status, ChunkStatus::stored);
  const auto refused = put(9);
  EXPECT_EQ(refused.status, ChunkStatus::beyond_window);
  EXPECT_EQ(refused.contiguous_through, 0u);
  EXPECT_NE(refused.reason.find("proto-17/run-1#9"), std::string::npos) << refused.reason;
  auto absurd = chunk("proto-17", "run-1", 0);
  absurd.sequence = ~std::uint64_t{0};
  absurd.seal();
  EXPECT_EQ(store_->store_chunk(absurd).status, ChunkStatus::beyond_window);
  EXPECT_EQ(stored_count(), 2u);
}

TEST_P(StoreOrder, FirstChunkMayArriveLateAndTheAckStaysEmptyUntilThen) {
  const auto early = put(2);
  EXPECT_EQ(early.status, ChunkStatus::stored);
  EXPECT_FALSE(early.contiguous_through.has_value());
  EXPECT_FALSE(store_->highest_contiguous(kRun).has_value());
  EXPECT_THROW(store_->chunks(kRun, 0, 0), InputError);
  EXPECT_EQ(put(1).contiguous_through, std::nullopt);
  EXPECT_EQ(put(0).contiguous_through, 2u);
}

}  // namespace
}  // namespace dynid::store::test
