// The spool: chunks persist before they are sent, acknowledgements prune them, a restart finds
// the unacknowledged ones in order, and a full spool says so instead of dropping anything.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <dynid/error.hpp>

#include "car_test_support.hpp"
#include "dynid/car/chunk_builder.hpp"
#include "dynid/car/spool.hpp"

namespace dynid::car {
namespace {

// Real chunks from the ChunkBuilder: `count` chunks of 10 rows x 3 channels.
std::vector<ingest::Chunk> make_chunks(const std::string& run, std::size_t count, double offset = 0.0) {
  std::vector<ingest::Chunk> out;
  ChunkBuilder b("car-1", run, 3, 10, [&](ingest::Chunk&& c) { out.push_back(std::move(c)); });
  for (std::uint64_t k = 0; k < 10 * count; ++k) {
    const double v[3] = {offset + static_cast<double>(k), 0.5 * static_cast<double>(k), -1.0};
    b.add_row(k, v, k % 7 != 3);
  }
  return out;
}

void expect_same(const ingest::Chunk& a, const ingest::Chunk& b) {
  EXPECT_EQ(a.vehicle, b.vehicle);
  EXPECT_EQ(a.run, b.run);
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.first_sample_index, b.first_sample_index);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.valid, b.valid);
  EXPECT_EQ(a.checksum, b.checksum);
}

std::vector<std::uint64_t> sequences(const Spool& s) {
  std::vector<std::uint64_t> out;
  for (const auto& e : s.pending_entries()) out.push_back(e.sequence);
  return out;
}

TEST(CarSpool, StoresAcknowledgementPrunesRestartResendsInOrder) {
  test::ScratchDir dir("spool");
  const auto chunks = make_chunks("r1", 5);
  std::uint64_t total = 0;
  {
    Spool spool(dir.path(), 1 << 20);
    for (const auto& c : chunks) spool.store(c);
    total = spool.bytes();
    EXPECT_EQ(total, 5 * ingest::encode_chunk(chunks[0]).size());
    const auto pending = spool.pending();
    ASSERT_EQ(pending.size(), 5U);
    for (std::size_t i = 0; i < 5; ++i) expect_same(pending[i], chunks[i]);
    spool.acknowledge("car-1", "r1", 2);
    EXPECT_EQ(sequences(spool), (std::vector<std::uint64_t>{3, 4}));
    EXPECT_EQ(spool.bytes(), total * 2 / 5);
    spool.acknowledge("car-1", "r1", 1);  // an older ack changes nothing
    EXPECT_EQ(spool.count(), 2U);
  }
  // A restart: the unacknowledged chunks are there, in order, byte for byte.
  Spool reopened(dir.path(), 1 << 20);
  EXPECT_EQ(reopened.bytes(), total * 2 / 5);
  EXPECT_EQ(reopened.acknowledged("car-1", "r1"), 2U);
  const auto pending = reopened.pending();
  ASSERT_EQ(pending.size(), 2U);
  expect_same(pending[0], chunks[3]);
  expect_same(pending[1], chunks[4]);
  reopened.acknowledge("car-1", "r1", 4);
  EXPECT_EQ(reopened.count(), 0U);
  EXPECT_EQ(reopened.bytes(), 0U);
}

TEST(CarSpool, RunsInterleaveInStorageOrderAndAcksArePerRun) {
  test::ScratchDir dir("spool-runs");
  const auto a = make_chunks("a", 3);
  const auto b = make_chunks("b", 3, 100.0);
  Spool spool(dir.path(), 1 << 20);
  for (std::size_t i = 0; i < 3; ++i) {
    spool.store(a[i]);
    spool.store(b[i]);
  }
  spool.acknowledge("car-1", "b", 1);
  const auto e = spool.pending_entries();
  ASSERT_EQ(e.size(), 4U);
  EXPECT_EQ(e[0].run + std::to_string(e[0].sequence), "a0");
  EXPECT_EQ(e[1].run + std::to_string(e[1].sequence), "a1");
  EXPECT_EQ(e[2].run + std::to_string(e[2].sequence), "a2");
  EXPECT_EQ(e[3].run + std::to_string(e[3].sequence), "b2");
}

TEST(CarSpool, ResendIsIdempotentConflictsAndAckedChunksAreRejected) {
  test::ScratchDir dir("spool-dup");
  const auto chunks = make_chunks("r", 2);
  Spool spool(dir.path(), 1 << 20);
  spool.store(chunks[0]);
  spool.store(chunks[0]);  // the same bytes again: a no-op
  EXPECT_EQ(spool.count(), 1U);
  ingest::Chunk other = chunks[0];
  other.samples(0, 0) = 42.0;
  other.seal();
  EXPECT_THROW(spool.store(other), InputError);
  spool.acknowledge("car-1", "r", 0);
  try {
    spool.store(chunks[0]);
    FAIL() << "an acknowledged chunk was stored again";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("car-1/r#0 is already acknowledged"), std::string::npos) << e.what();
  }
  EXPECT_EQ(spool.count(), 0U);
}

TEST(CarSpool, AFullSpoolSaysSoAndDropsNothing) {
  test::ScratchDir dir("spool-full");
  const auto chunks = make_chunks("r", 6);
  const std::uint64_t size = ingest::encode_chunk(chunks[0]).size();
  Spool spool(dir.path(), 4 * size + size / 2);  // room for four chunks
  for (std::size_t i = 0; i < 4; ++i) spool.store(chunks[i]);
  try {
    spool.store(chunks[4]);
    FAIL() << "the fifth chunk fit";
  } catch (const SpoolFull& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("spool full: " + std::to_string(4 * size) + " bytes of " + std::to_string(4 * size + size / 2)),
              std::string::npos) << msg;
    EXPECT_NE(msg.find("server unreachable since 20"), std::string::npos) << msg;  // a UTC date
    EXPECT_NE(msg.find("(4 chunks unacknowledged)"), std::string::npos) << msg;
  }
  EXPECT_EQ(spool.count(), 4U);  // nothing was dropped to make room
  EXPECT_EQ(sequences(spool), (std::vector<std::uint64_t>{0, 1, 2, 3}));
  // The server comes back: an ack frees room and the chunk goes in.
  spool.acknowledge("car-1", "r", 0);
  EXPECT_NO_THROW(spool.store(chunks[4]));
  EXPECT_EQ(sequences(spool), (std::vector<std::uint64_t>{1, 2, 3, 4}));
}

// A chunk set aside (refused for good by the server) keeps its bytes and reason in the refused
// table, its stand-in takes its place in order; a run set aside leaves nothing to resend, and
// both survive a restart.
TEST(CarSpool, SetAsideKeepsTheRefusedChunkAndPutsItsStandInInItsPlace) {
  test::ScratchDir dir("spool-set-aside");
  const auto chunks = make_chunks("r1", 3);
  const auto other = make_chunks("r2", 2);
  {
    Spool spool(dir.path(), 1 << 20);
    for (const auto& c : chunks) spool.store(c);
    for (const auto& c : other) spool.store(c);
    ingest::Chunk stand_in = chunks[1];
    stand_in.samples.setZero();
    std::fill(stand_in.valid.begin(), stand_in.valid.end(), std::uint8_t{0});
    stand_in.seal();
    spool.set_aside(stand_in, "value past the limit");
    EXPECT_EQ(sequences(spool), (std::vector<std::uint64_t>{0, 1, 2, 0, 1}));
    expect_same(*spool.load("car-1", "r1", 1), stand_in);
    ingest::Chunk missing = stand_in;
    missing.sequence = 9;
    EXPECT_THROW(spool.set_aside(missing, "x"), InputError);
    EXPECT_EQ(spool.set_aside_run("car-1", "r2", "run name taken"), 2U);
    EXPECT_EQ(sequences(spool), (std::vector<std::uint64_t>{0, 1, 2}));
    EXPECT_EQ(spool.bytes(), 3 * ingest::encode_chunk(chunks[0]).size());
  }
  Spool again(dir.path(), 1 << 20);
  const auto refused = again.refused();
  ASSERT_EQ(refused.size(), 3U);
  EXPECT_EQ(refused[0].run, "r1");
  EXPECT_EQ(refused[0].sequence, 1U);
  EXPECT_EQ(refused[0].reason, "value past the limit");
  EXPECT_EQ(refused[1].run, "r2");
  EXPECT_EQ(refused[2].reason, "run name taken");
  EXPECT_EQ(sequences(again), (std::vector<std::uint64_t>{0, 1, 2}));
}

}  // namespace
}  // namespace dynid::car
