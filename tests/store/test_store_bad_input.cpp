// Bad input on every backend (store_contract.hpp): a chunk of an unknown run, a chunk that
// fails validation, a new chunk for a closed run, an invalid announcement. Each is InputError
// naming what and where, and changes nothing.
#include <gtest/gtest.h>

#include <limits>

#include "dynid/error.hpp"
#include "store_contract.hpp"

namespace dynid::store::test {

void StoreBadInput::expect_unchanged() {
  EXPECT_EQ(store_->list_vehicles(), std::vector<std::string>{"proto-17"});
  const auto runs = store_->list_runs("proto-17");
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].chunks_stored, 1u);
  EXPECT_EQ(runs[0].contiguous_through, 0u);
}

void StoreBadInput::expect_rejected(const ingest::Chunk& c, const std::string& words) {
  try {
    store_->store_chunk(c);
    ADD_FAILURE() << "accepted a bad chunk (" << words << ")";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
  expect_unchanged();
}

namespace {

const RunKey kRun{"proto-17", "run-1"};

TEST_P(StoreBadInput, ChunkOfAnUnknownRunIsRejected) {
  expect_rejected(chunk("proto-17", "run-9", 1), "proto-17/run-9");
  expect_rejected(chunk("ghost", "run-1", 1), "ghost/run-1");
}

TEST_P(StoreBadInput, ChunkThatFailsValidationIsRejected) {
  auto nan = chunk("proto-17", "run-1", 1);
  nan.samples(3, 1) = std::numeric_limits<double>::quiet_NaN();
  nan.seal();
  expect_rejected(nan, "proto-17/run-1#1");

  auto tampered = chunk("proto-17", "run-1", 1);
  tampered.samples(0, 0) += 1.0;  // checksum no longer matches
  expect_rejected(tampered, "proto-17/run-1#1");

  auto narrow = chunk("proto-17", "run-1", 1);
  narrow.samples.conservativeResize(Eigen::NoChange, 2);
  narrow.seal();
  expect_rejected(narrow, "proto-17/run-1#1");
}

TEST_P(StoreBadInput, NewChunkForAClosedRunIsRejectedButDuplicatesStillAck) {
  store_->close_run(kRun);
  store_->close_run(kRun);  // idempotent
  expect_rejected(chunk("proto-17", "run-1", 1), "closed");
  EXPECT_EQ(store_->store_chunk(chunk("proto-17", "run-1", 0)).status, ChunkStatus::duplicate);
}

TEST_P(StoreBadInput, InvalidAnnouncementIsRejected) {
  auto bad = announcement("proto-17", "run-2");
  bad.sample_rate_hz = -1.0;
  EXPECT_THROW(store_->add_run(bad), InputError);
  expect_unchanged();
}

}  // namespace
}  // namespace dynid::store::test
