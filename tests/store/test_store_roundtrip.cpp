// Round trips through every backend (store_contract.hpp): runs, chunks, ledger marks,
// checkpoints, estimates, and everything still there after the store is closed and opened again.
#include <gtest/gtest.h>

#include "dynid/error.hpp"
#include "dynid/store/store.hpp"
#include "store_contract.hpp"

namespace dynid::store::test {
namespace {

const RunKey kRun{"proto-17", "run-1"};

TEST_P(StoreRoundTrip, RunsAreAddedOnceAndConflictingAnnouncementsRejected) {
  Store store = open();
  EXPECT_EQ(store.add_run(announcement("proto-17", "run-1")), AddRunResult::added);
  EXPECT_EQ(store.add_run(announcement("proto-17", "run-1")), AddRunResult::already_known);
  EXPECT_EQ(store.add_run(announcement("proto-17", "run-2")), AddRunResult::added);
  EXPECT_EQ(store.add_run(announcement("mule-3", "run-1")), AddRunResult::added);

  auto other = announcement("proto-17", "run-1");
  other.sample_rate_hz = 200.0;
  try {
    store.add_run(other);
    FAIL() << "a conflicting announcement was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("proto-17/run-1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(store.announcement(kRun).sample_rate_hz, 100.0);
  EXPECT_EQ(store.announcement(kRun).channels[2].name, "steering_angle");
  EXPECT_EQ((store.list_vehicles()), (std::vector<std::string>{"mule-3", "proto-17"}));
  const auto runs = store.list_runs("proto-17");
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].run, "run-1");
  EXPECT_EQ(runs[1].run, "run-2");
  EXPECT_FALSE(runs[0].contiguous_through.has_value());
  EXPECT_THROW(store.list_runs("nobody"), InputError);
}

TEST_P(StoreRoundTrip, ChunksComeBackBitForBitInOrder) {
  Store store = open();
  store.add_run(announcement("proto-17", "run-1"));
  for (std::uint64_t s = 0; s < 20; ++s) {
    const auto result = store.store_chunk(chunk("proto-17", "run-1", s));
    ASSERT_EQ(result.status, ChunkStatus::stored);
    EXPECT_EQ(result.contiguous_through, s);
  }
  EXPECT_EQ(store.highest_contiguous(kRun), 19u);
  auto stream = store.chunks(kRun, 5, 19);
  for (std::uint64_t s = 5; s <= 19; ++s) {
    const auto c = stream.next();
    ASSERT_TRUE(c.has_value()) << s;
    EXPECT_TRUE(same(*c, chunk("proto-17", "run-1", s))) << s;
  }
  EXPECT_FALSE(stream.next().has_value());
  EXPECT_FALSE(store.chunks(kRun, 3, 2).next().has_value());  // empty range
  EXPECT_THROW(store.chunks(kRun, 0, 20), InputError);        // past the contiguous prefix
}

TEST_P(StoreRoundTrip, CheckpointsMoveTheFoldedMarkAndFollowTheRules) {
  Store store = open();
  store.add_run(announcement("proto-17", "run-1"));
  for (std::uint64_t s = 0; s < 10; ++s) store.store_chunk(chunk("proto-17", "run-1", s));
  EXPECT_FALSE(store.latest_checkpoint(kRun).has_value());
  EXPECT_FALSE(store.folded_through(kRun).has_value());

  store.mark_folded(kRun, 2);
  EXPECT_EQ(store.folded_through(kRun), 2u);
  store.save_checkpoint(kRun, 4, "state after 0..4");
  EXPECT_EQ(store.folded_through(kRun), 4u);
  store.save_checkpoint(kRun, 4, "state after 0..4");  // the same again: no-op
  EXPECT_THROW(store.save_checkpoint(kRun, 4, "something else"), InputError);
  EXPECT_THROW(store.save_checkpoint(kRun, 3, "older"), InputError);
  EXPECT_THROW(store.save_checkpoint(kRun, 10, "not stored yet"), InputError);
  EXPECT_THROW(store.mark_folded(kRun, 3), InputError);   // backwards: would fold twice
  EXPECT_THROW(store.mark_folded(kRun, 10), InputError);  // not stored
  store.save_checkpoint(kRun, 9, std::string("\0binary\xff", 8));

  const auto latest = store.latest_checkpoint(kRun);
  ASSERT_TRUE(latest.has_value());
  EXPECT_EQ(latest->folded_through, 9u);
  EXPECT_EQ(latest->state, std::string("\0binary\xff", 8));
  EXPECT_EQ(store.folded_through(kRun), 9u);
}

// The server's replay: read a chunk, fold it, mark it, checkpoint now and then, store new
// chunks as they arrive, all while the stream is open on the same connection.
TEST_P(StoreRoundTrip, ReplayMarksFoldsCheckpointsAndStoresWhileStreaming) {
  Store store = open();
  store.add_run(announcement("proto-17", "run-1"));
  for (std::uint64_t s = 0; s < 6; ++s) store.store_chunk(chunk("proto-17", "run-1", s));
  auto stream = store.chunks(kRun, 0, 5);
  std::uint64_t arriving = 6;
  while (const auto c = stream.next()) {
    store.mark_folded(kRun, c->sequence);
    if (c->sequence % 2 == 1)
      store.save_checkpoint(kRun, c->sequence, "after " + std::to_string(c->sequence));
    EXPECT_EQ(store.store_chunk(chunk("proto-17", "run-1", arriving++)).status,
              ChunkStatus::stored);
  }
  EXPECT_EQ(store.folded_through(kRun), 5u);
  EXPECT_EQ(store.latest_checkpoint(kRun)->state, "after 5");
  EXPECT_EQ(store.highest_contiguous(kRun), 11u);
}

TEST_P(StoreRoundTrip, EstimateHistoryKeepsEveryRecordInTimeOrder) {
  Store store = open();
  store.add_run(announcement("proto-17", "run-1"));
  store.record_estimate({"proto-17", "lateral_bicycle", "run-1", 2000, "table B"});
  store.record_estimate({"proto-17", "lateral_bicycle", "run-1", 1000, "table A"});
  store.record_estimate({"proto-17", "longitudinal", "pool:all", 1500, "other model"});
  const auto history = store.estimate_history("proto-17", "lateral_bicycle");
  ASSERT_EQ(history.size(), 2u);
  EXPECT_EQ(history[0].encoded, "table A");
  EXPECT_EQ(history[1].encoded, "table B");
  EXPECT_EQ(history[1].scope, "run-1");
  EXPECT_THROW(store.record_estimate({"unknown", "m", "run-1", 1, "x"}), InputError);
}

TEST_P(StoreRoundTrip, EverythingSurvivesCloseAndReopenAndFoldsRestartAtTheCheckpoint) {
  {
    Store store = open();
    store.add_run(announcement("proto-17", "run-1"));
    for (std::uint64_t s = 0; s < 8; ++s) store.store_chunk(chunk("proto-17", "run-1", s));
    store.store_chunk(chunk("proto-17", "run-1", 10));  // ahead of a gap
    store.save_checkpoint(kRun, 3, "checkpoint");
    store.mark_folded(kRun, 6);  // folded in memory only: lost with the process
    store.record_estimate({"proto-17", "lateral_bicycle", "run-1", 5, "estimate"});
    store.close_run({"proto-17", "run-1"});
  }
  Store store = open();
  EXPECT_EQ(store.highest_contiguous(kRun), 7u);
  EXPECT_EQ(store.folded_through(kRun), 3u);
  EXPECT_EQ(store.latest_checkpoint(kRun)->state, "checkpoint");
  const auto runs = store.list_runs("proto-17");
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_TRUE(runs[0].closed);
  EXPECT_EQ(runs[0].chunks_stored, 9u);
  EXPECT_EQ(store.estimate_history("proto-17", "lateral_bicycle").at(0).encoded, "estimate");
  auto stream = store.chunks(kRun, 4, 7);  // the replay after the checkpoint
  for (std::uint64_t s = 4; s <= 7; ++s) {
    EXPECT_TRUE(same(*stream.next(), chunk("proto-17", "run-1", s)));
  }
  EXPECT_FALSE(stream.next().has_value());
}

}  // namespace
}  // namespace dynid::store::test
