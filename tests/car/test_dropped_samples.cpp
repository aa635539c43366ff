// A sample no chunk may carry (a float signal reading 1e20 or NaN: a sensor fault, a bit error
// the CRC missed) is left out where it enters, counted and named with its channel; every chunk
// of the run is one the server accepts, and the rows around it stay valid (dropped_samples.hpp).
// A channel the log never fills is named with where it was to come from (pipeline.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include <dynid/ingest/chunk.hpp>

#include "car_test_support.hpp"
#include "dynid/car/pipeline.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {
namespace {

// One message of two IEEE signals: a double speed (m/s) and a float acceleration.
constexpr const char* kDbc =
    "VERSION \"\"\n\nNS_ :\n\nBS_:\n\nBU_: ECU\n\n"
    "BO_ 256 Motion: 8 ECU\n"
    " SG_ Speed : 0|64@1- (1,0) [0|0] \"m/s\" ECU\n\n"
    "BO_ 257 Accel: 4 ECU\n"
    " SG_ LongAccel : 0|32@1- (1,0) [0|0] \"m/s2\" ECU\n\n"
    "SIG_VALTYPE_ 256 Speed : 2;\n"
    "SIG_VALTYPE_ 257 LongAccel : 1;\n";

VehicleProfile float_profile(const test::ScratchDir& dir) {
  const auto dbc = dir.path() / "float.dbc";
  std::ofstream(dbc) << kDbc;
  return parse_vehicle_profile(
      "[vehicle]\nid = \"float-car\"\ndbc = \"" + dbc.string() +
          "\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 1.0\n[spool]\ndirectory = "
          "\"spool\"\nmax_bytes = 1000000\n"
          "[[channels]]\nname = \"vx\"\nmessage = \"Motion\"\nsignal = \"Speed\"\n"
          "[[channels]]\nname = \"ax\"\nmessage = \"Accel\"\nsignal = \"LongAccel\"\n",
      dir.path() / "float.toml");
}

can::Frame frame(std::uint32_t id, double t, const void* bytes, std::size_t length) {
  can::Frame f;
  f.id = id;
  f.length = static_cast<std::uint8_t>(length);
  std::memcpy(f.data.data(), bytes, length);
  f.set_interface_name("can0");
  f.timestamp = t;
  return f;
}

TEST(DroppedSamples, OneValueNoChunkMayCarryIsLeftOutAndTheRunDelivered) {
  test::ScratchDir dir("dropped-samples");
  const VehicleProfile profile = float_profile(dir);
  std::vector<ingest::Chunk> chunks;
  CarPipeline pipe(profile, "r1", [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
  for (int i = 0; i < 1000; ++i) {  // 10 s at 100 Hz
    const double t = i * 0.01;
    const double speed = i == 420 ? 1e20 : 20.0 + 0.01 * i;
    const float accel = i == 610   ? std::numeric_limits<float>::quiet_NaN()
                        : i == 700 ? 3e38F
                                   : 0.5F;
    pipe.on_frame(frame(256, t, &speed, 8));
    pipe.on_frame(frame(257, t + 0.001, &accel, 4));
  }
  pipe.finish();
  ASSERT_GE(chunks.size(), 9U);
  const ingest::RunAnnouncement announcement = profile.announcement("r1");
  std::size_t rows = 0, invalid = 0;
  for (const ingest::Chunk& c : chunks) {
    EXPECT_NO_THROW(ingest::validate_and_encode(c, announcement, ingest::ChunkLimits{}))
        << c.sequence;
    for (Eigen::Index k = 0; k < c.samples.rows(); ++k) {
      ++rows;
      if (c.valid[static_cast<std::size_t>(k)] == 0) ++invalid;
      EXPECT_LT(std::abs(c.samples(k, 0)), 100.0)
          << "row " << c.first_sample_index + static_cast<std::uint64_t>(k);
    }
  }
  EXPECT_GE(rows, 990U);
  EXPECT_LE(invalid, 4U);  // one missing sample is interpolated across, not a gap
  EXPECT_EQ(pipe.mapper_stats().out_of_range, 2U);
  EXPECT_EQ(pipe.mapper_stats().non_finite, 1U);
  const std::vector<std::string> report = pipe.dropped_report();
  ASSERT_EQ(report.size(), 2U);
  EXPECT_NE(report[0].find("channel 'vx': 1 sample left out (the first 1e+20, beyond the 1e+15 a "
                           "chunk may carry, at "
                           "4.200 s"),
            std::string::npos)
      << report[0];
  EXPECT_NE(report[1].find("channel 'ax': 2 samples left out (the first NaN, at 6.101 s"),
            std::string::npos)
      << report[1];
}

// A channel the log never fills makes every row invalid: the report names it and where it was
// to come from, instead of a bare count of invalid rows.
TEST(DroppedSamples, AChannelThatNeverGetsAValueIsNamed) {
  test::ScratchDir dir("never-filled");
  const VehicleProfile profile = float_profile(dir);
  std::vector<ingest::Chunk> chunks;
  CarPipeline pipe(profile, "r1", [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
  for (int i = 0; i < 300; ++i) {  // Motion only: no Accel frame, so no ax
    const double speed = 20.0;
    pipe.on_frame(frame(256, i * 0.01, &speed, 8));
  }
  pipe.finish();
  const std::vector<std::string> report = pipe.missing_report();
  ASSERT_EQ(report.size(), 1U);
  EXPECT_NE(report[0].find("channel 'ax' had no value in "), std::string::npos) << report[0];
  EXPECT_NE(
      report[0].find(
          "(no sample at all from message 'Accel', signal LongAccel): those rows are invalid"),
      std::string::npos)
      << report[0];
}

// The other channel types: a 64-bit integer signal at 2^63 (9.2e18) and a scaled 16-bit one
// whose factor puts its top value at 6.6e16 go past the limit as the double and the float do:
// left out where they enter, every chunk one the server takes, each named with its value.
TEST(DroppedSamples, IntegerAndScaledSignalsPastTheLimitAreLeftOutToo) {
  test::ScratchDir dir("dropped-integer");
  const auto dbc = dir.path() / "integer.dbc";
  std::ofstream(dbc) << "VERSION \"\"\n\nNS_ :\n\nBS_:\n\nBU_: ECU\n\n"
                        "BO_ 258 Wheel: 8 ECU\n"
                        " SG_ WhlSpd : 0|64@1+ (1,0) [0|0] \"m/s\" ECU\n\n"
                        "BO_ 259 Brake: 2 ECU\n"
                        " SG_ Pressure : 0|16@1+ (1e12,0) [0|0] \"Pa\" ECU\n";
  const VehicleProfile profile = parse_vehicle_profile(
      "[vehicle]\nid = \"integer-car\"\ndbc = \"" + dbc.string() +
          "\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 1.0\n[spool]\ndirectory = "
          "\"spool\"\nmax_bytes = 1000000\n"
          "[[channels]]\nname = \"wheel_speed_fl\"\nmessage = \"Wheel\"\nsignal = \"WhlSpd\"\n"
          "[[channels]]\nname = \"brake_pressure\"\nmessage = \"Brake\"\nsignal = \"Pressure\"\n",
      dir.path() / "integer.toml");
  std::vector<ingest::Chunk> chunks;
  CarPipeline pipe(profile, "r1", [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
  for (int i = 0; i < 1000; ++i) {
    const double t = i * 0.01;
    const std::uint64_t wheel = i == 300 ? std::uint64_t{1} << 63 : 20;
    const std::uint16_t pressure = i == 500 ? 0xFFFF : 0;
    pipe.on_frame(frame(258, t, &wheel, 8));
    pipe.on_frame(frame(259, t + 0.001, &pressure, 2));
  }
  pipe.finish();
  const ingest::RunAnnouncement announcement = profile.announcement("r1");
  std::size_t rows = 0;
  for (const ingest::Chunk& c : chunks) {
    EXPECT_NO_THROW(ingest::validate_and_encode(c, announcement, ingest::ChunkLimits{}))
        << c.sequence;
    rows += static_cast<std::size_t>(c.samples.rows());
  }
  EXPECT_GE(rows, 990U);
  EXPECT_EQ(pipe.mapper_stats().out_of_range, 2U);
  const std::vector<std::string> report = pipe.dropped_report();
  ASSERT_EQ(report.size(), 2U) << ::testing::PrintToString(report);
  const std::string both = report[0] + "\n" + report[1];
  EXPECT_NE(both.find("channel 'wheel_speed_fl': 1 sample left out (the first 9.22e+18, beyond the "
                      "1e+15 a chunk "
                      "may carry, at 3.000 s"),
            std::string::npos)
      << both;
  EXPECT_NE(both.find("channel 'brake_pressure': 1 sample left out (the first 6.55e+16, beyond the "
                      "1e+15 a chunk "
                      "may carry, at 5.001 s"),
            std::string::npos)
      << both;
}

}  // namespace
}  // namespace dynid::car
