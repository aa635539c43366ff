// Chunk and announcement contract: validation names the place and reason, the encodings are
// exact and detect corruption, absurd sizes are refused without allocating them.
#include "dynid/ingest/chunk.hpp"

#include <zlib.h>

#include <cstring>
#include <limits>

#include "dynid/ingest/run_announcement.hpp"
#include "ingest_test_support.hpp"

namespace dynid::ingest {
namespace {

using test::expect_input_error;

class ChunkValidation : public testing::Test {
 protected:
  test::TestRun run = test::make_run(400);
  Chunk chunk = test::cut(run, 7, 100, 50);
  void reseal_and_expect(const std::vector<std::string>& words) {
    chunk.seal();
    expect_input_error([&] { validate_chunk(chunk, run.announcement); }, words);
  }
};

TEST_F(ChunkValidation, AcceptsAGoodChunk) {
  EXPECT_NO_THROW(validate_chunk(chunk, run.announcement));
}

TEST_F(ChunkValidation, NamesANonFiniteValueByRowAndChannel) {
  chunk.samples(3, 1) = std::numeric_limits<double>::quiet_NaN();
  reseal_and_expect({"proto-17/run-0042#7", "row 3", "sample 103", "'ax'", "NaN"});
  chunk.samples(3, 1) = 0.0;
  chunk.samples(9, 4) = -std::numeric_limits<double>::infinity();
  reseal_and_expect({"row 9", "'engine_torque'", "infinite"});
  chunk.samples(9, 4) = 1e300;  // finite but absurd
  reseal_and_expect({"row 9", "'engine_torque'", "exceeds the limit"});
}

TEST_F(ChunkValidation, NonFiniteIsRejectedInGapsToo) {
  chunk.valid[5] = 0;
  chunk.samples(5, 0) = std::numeric_limits<double>::quiet_NaN();
  reseal_and_expect({"row 5", "'vx'"});
}

TEST_F(ChunkValidation, RejectsWrongDimensions) {
  chunk.samples.conservativeResize(Eigen::NoChange, 5);
  reseal_and_expect({"5 channels, the run announced 6"});
  chunk = test::cut(run, 7, 100, 50);
  chunk.valid.pop_back();
  reseal_and_expect({"49 valid flags for 50 rows"});
  chunk = test::cut(run, 7, 100, 50);
  chunk.valid[2] = 2;
  reseal_and_expect({"row 2", "valid flag 2"});
  chunk.samples.resize(0, 6);
  chunk.valid.clear();
  reseal_and_expect({"no sample rows"});
}

TEST_F(ChunkValidation, RejectsAbsurdSizes) {
  ChunkLimits limits;
  limits.max_rows = 20;
  expect_input_error([&] { validate_chunk(chunk, run.announcement, limits); },
                     {"50 rows exceed the limit of 20"});
  limits = {};
  limits.max_channels = 4;
  expect_input_error([&] { validate_chunk(chunk, run.announcement, limits); },
                     {"6 channels exceed the limit of 4"});
}

TEST_F(ChunkValidation, RejectsWrongIdsAndABadChecksum) {
  chunk.vehicle = "proto-18";
  reseal_and_expect({"vehicle 'proto-18'", "'proto-17'"});
  chunk.vehicle = run.announcement.vehicle;
  chunk.run = "run-9";
  reseal_and_expect({"run 'run-9'"});
  chunk.run = run.announcement.run;
  chunk.seal();
  chunk.samples(10, 2) += 1e-9;  // changed after sealing
  expect_input_error([&] { validate_chunk(chunk, run.announcement); }, {"checksum", "corrupted"});
}

TEST(ChunkEncoding, RoundTripIsExact) {
  test::TestRun run = test::make_run(1600);
  Chunk c = test::cut(run, 3, 1490, 60);  // spans the gap at 1500
  c.samples(0, 0) = -0.0;
  c.samples(1, 1) = std::numeric_limits<double>::denorm_min();
  c.samples(2, 2) = std::nextafter(1.0, 2.0);
  c.seal();
  const Chunk d = decode_chunk(encode_chunk(c));
  EXPECT_EQ(d.vehicle, c.vehicle);
  EXPECT_EQ(d.run, c.run);
  EXPECT_EQ(d.sequence, c.sequence);
  EXPECT_EQ(d.first_sample_index, c.first_sample_index);
  EXPECT_EQ(d.valid, c.valid);
  EXPECT_EQ(d.checksum, c.checksum);
  ASSERT_EQ(d.samples.rows(), c.samples.rows());
  ASSERT_EQ(d.samples.cols(), c.samples.cols());
  EXPECT_EQ(std::memcmp(d.samples.data(), c.samples.data(),
                        sizeof(double) * static_cast<std::size_t>(c.samples.size())),
            0);  // bit patterns, -0.0 included
  EXPECT_EQ(encode_chunk(d), encode_chunk(c));
}

TEST(ChunkEncoding, DetectsCorruptionTruncationAndTrailingBytes) {
  test::TestRun run = test::make_run(100);
  const std::string bytes = encode_chunk(test::cut(run, 0, 0, 20));
  for (std::size_t i = 0; i < bytes.size(); i += 7) {  // a flipped bit anywhere
    std::string bad = bytes;
    bad[i] = static_cast<char>(bad[i] ^ 0x10);
    EXPECT_THROW((void)decode_chunk(bad), InputError) << "byte " << i;
  }
  for (std::size_t n = 0; n < bytes.size(); n += 5)
    EXPECT_THROW((void)decode_chunk(bytes.substr(0, n)), InputError) << n << " bytes";
  expect_input_error([&] { (void)decode_chunk(bytes + "x"); }, {"checksum"});
  expect_input_error([&] { (void)decode_chunk("DYNIDCHK\x02"); }, {"truncated"});
}

// Re-seals raw bytes (the checksum covers everything before it) to reach the size checks.
std::string resealed(std::string body) {
  const auto crc = static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())));
  body.append(reinterpret_cast<const char*>(&crc), sizeof(crc));
  return body;
}

// A 4-row chunk's encoding without its checksum, with its row and column counts set (they sit
// after magic (8), version (2), two strings and two u64).
std::string with_counts(std::uint64_t rows, std::uint64_t cols) {
  test::TestRun run = test::make_run(100);
  std::string bytes = encode_chunk(test::cut(run, 0, 0, 4));
  bytes.resize(bytes.size() - 4);
  const std::size_t rows_at =
      8 + 2 + 4 + run.announcement.vehicle.size() + 4 + run.announcement.run.size() + 16;
  std::memcpy(bytes.data() + rows_at, &rows, sizeof(rows));
  std::memcpy(bytes.data() + rows_at + sizeof(rows), &cols, sizeof(cols));
  return bytes;
}

TEST(ChunkEncoding, RefusesAbsurdSizesWithoutAllocating) {
  const std::uint64_t huge = std::uint64_t{1} << 60;
  expect_input_error([&] { (void)decode_chunk(resealed(with_counts(huge, 6))); },
                     {"samples claimed"});
  expect_input_error([&] { (void)decode_chunk(resealed("DYNIDCHK\x07")); }, {"version"});
  expect_input_error([&] { (void)decode_chunk(resealed("NOTACHNK\x01")); }, {"bad magic"});
}

// Zero columns (or zero rows) carry no sample bytes, so the other count was not bounded: 2^60
// rows of nothing hung the decoder's loops (found by tests/fuzz/fuzz_chunk, whose corpus keeps
// the input as timeout-zero-columns.chunk).
TEST(ChunkEncoding, RefusesAbsurdCountsBesideAZeroDimension) {
  const std::uint64_t huge = std::uint64_t{1} << 60;
  expect_input_error([&] { (void)decode_chunk(resealed(with_counts(huge, 0))); },
                     {"samples claimed"});
  expect_input_error([&] { (void)decode_chunk(resealed(with_counts(0, huge))); },
                     {"samples claimed"});
}

TEST(RunAnnouncement, ValidatesFieldsByName) {
  const RunAnnouncement good = test::announcement_for({});
  EXPECT_NO_THROW(good.validate());
  RunAnnouncement a = good;
  a.vehicle.clear();
  expect_input_error([&] { a.validate(); }, {"vehicle", "empty"});
  a = good;
  a.sample_rate_hz = std::numeric_limits<double>::quiet_NaN();
  expect_input_error([&] { a.validate(); }, {"sample_rate_hz"});
  a = good;
  a.channels.push_back({"vx", "m/s"});
  expect_input_error([&] { a.validate(); }, {"channels[6]", "'vx' is announced twice"});
  a = good;
  a.models[1].constants["gravity"] = std::numeric_limits<double>::infinity();
  expect_input_error([&] { a.validate(); }, {"models[1]", "'gravity'", "not finite"});
  a = good;
  a.preprocessing.butterworth_order = 9;
  expect_input_error([&] { a.validate(); }, {"butterworth_order", "1..8"});
  a = good;
  a.preprocessing.cutoff_hz = 60.0;
  expect_input_error([&] { a.validate(); }, {"cutoff_hz", "Nyquist"});
  a = good;
  a.preprocessing.filter_tolerance = 0.1;
  expect_input_error([&] { a.validate(); }, {"filter_tolerance"});
  EXPECT_THROW((void)good.column_of("vy"), InputError);
  EXPECT_EQ(good.column_of("gear"), 5u);
  EXPECT_DOUBLE_EQ(good.preprocessing.cutoff(100.0), 8.0);
}

TEST(RunAnnouncement, EncodingRoundTripsAndDetectsCorruption) {
  RunAnnouncement a = test::announcement_for({});
  a.preprocessing.cutoff_hz = 7.25;
  a.preprocessing.unfiltered = {"gear"};
  const std::string bytes = encode_announcement(a);
  const RunAnnouncement b = decode_announcement(bytes);
  EXPECT_EQ(encode_announcement(b), bytes);
  EXPECT_EQ(b.models[0].constants, a.models[0].constants);
  EXPECT_EQ(b.models[1].effects, a.models[1].effects);
  EXPECT_EQ(b.channels[3].unit, "rad/s");
  EXPECT_EQ(b.preprocessing.cutoff_hz, 7.25);
  for (std::size_t i = 0; i < bytes.size(); i += 11) {
    std::string bad = bytes;
    bad[i] = static_cast<char>(bad[i] ^ 0x01);
    EXPECT_THROW((void)decode_announcement(bad), InputError) << "byte " << i;
  }
  EXPECT_THROW((void)decode_announcement(bytes.substr(0, bytes.size() - 1)), InputError);
}

// Issue 16 item 5: the vehicle profile's declared sensor noise rides in the announcement. An
// announcement without it encodes as before (version 1, so stored announcements and
// checkpoints still match); with it, as version 2, which this build reads too.
TEST(RunAnnouncement, DeclaredChannelNoiseIsValidatedAndEncoded) {
  RunAnnouncement a = test::announcement_for({});
  const std::string plain = encode_announcement(a);
  EXPECT_EQ(plain.substr(8, 2), std::string("\x01\x00", 2));  // after the magic: version 1
  a.preprocessing.channel_noise = {{"vx", 0.02}, {"gear", 0.5}};
  EXPECT_NO_THROW(a.validate());
  const std::string bytes = encode_announcement(a);
  EXPECT_EQ(bytes.substr(8, 2), std::string("\x02\x00", 2));
  const RunAnnouncement b = decode_announcement(bytes);
  EXPECT_EQ(b.preprocessing.channel_noise, a.preprocessing.channel_noise);
  EXPECT_EQ(encode_announcement(b), bytes);
  EXPECT_TRUE(decode_announcement(plain).preprocessing.channel_noise.empty());
  a.preprocessing.channel_noise = {{"vy", 0.02}};
  expect_input_error([&] { a.validate(); }, {"channel_noise 'vy'", "not an announced channel"});
  a.preprocessing.channel_noise = {{"vx", 0.0}};
  expect_input_error([&] { a.validate(); }, {"channel_noise 'vx'", "finite std > 0"});
}

}  // namespace
}  // namespace dynid::ingest
