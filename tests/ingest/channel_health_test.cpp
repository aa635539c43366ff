// The channel-health rules (ingest/channel_health.hpp) at their edges, on short runs built here:
// what a car holds exactly is no finding (a rest value, a gear, a steady yaw rate), a held span
// must be long and a large share, and the quantum is the channel's own smallest step.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "dynid/ingest/channel_health.hpp"

namespace dynid::ingest {
namespace {

// `seconds` of one channel at 100 Hz, every sample valid.
RecordedRun one_channel(const std::string& name, const std::string& unit, double seconds,
                        const std::function<double(double)>& value) {
  RecordedRun run;
  run.announcement.vehicle = "v";
  run.announcement.run = "r";
  run.announcement.sample_rate_hz = 100.0;
  run.announcement.channels = {{name, unit}};
  const auto n = static_cast<Eigen::Index>(seconds * 100.0);
  run.samples.resize(n, 1);
  for (Eigen::Index i = 0; i < n; ++i) run.samples(i, 0) = value(static_cast<double>(i) / 100.0);
  run.valid.assign(static_cast<std::size_t>(n), 1);
  return run;
}

// A smooth signal quantised at 0.01, as a DBC signal of that resolution decodes.
double quantised(double x) {
  return 0.01 * std::round(x / 0.01);
}

TEST(ChannelHealthRules, OnlyAChannelThatHoldsOnlyAtRestIsStuckOffIt) {
  EXPECT_TRUE(channel_health(one_channel("ay", "m/s^2", 30.0, [](double) {
                return 0.0;
              })).findings.empty());
  EXPECT_TRUE(channel_health(one_channel("az", "m/s^2", 30.0, [](double) {
                return 9.81;
              })).findings.empty());
  EXPECT_TRUE(
      channel_health(one_channel("gear", "-", 30.0, [](double) { return 3.0; })).findings.empty());
  EXPECT_TRUE(channel_health(one_channel("road_grade", "rad", 30.0, [](double) {
                return 0.05;
              })).findings.empty());
  // Steady cornering: the yaw rate holds, but not on a channel that holds only at rest.
  EXPECT_TRUE(channel_health(one_channel("yaw_rate", "rad/s", 30.0, [](double) {
                return 0.3;
              })).findings.empty());
  EXPECT_EQ(channel_health(one_channel("pitch_rate", "rad/s", 30.0, [](double) { return 0.3; }))
                .findings.size(),
            1u);
}

TEST(ChannelHealthRules, AHeldSpanMustBeLongAndALargeShare) {
  const auto held_from = [](double start) {
    return [start](double t) {
      return t < start ? quantised(std::sin(t)) : quantised(std::sin(start));
    };
  };
  // 40 % of the run held: not a large share.
  EXPECT_TRUE(channel_health(one_channel("ax", "m/s^2", 30.0, held_from(18.0))).findings.empty());
  // 60 % of a 6 s run (3.6 s): not long enough.
  EXPECT_TRUE(channel_health(one_channel("ax", "m/s^2", 6.0, held_from(2.4))).findings.empty());
  // 60 % of a 30 s run.
  const RunHealth held = channel_health(one_channel("ax", "m/s^2", 30.0, held_from(12.0)));
  ASSERT_EQ(held.findings.size(), 1u);
  EXPECT_EQ(held.findings[0].kind, HealthFinding::kConstant);
  EXPECT_NEAR(held.findings[0].from_s, 12.0, 0.1);  // the adjacent level before joins it
  EXPECT_NEAR(held.findings[0].share, 0.6, 0.01);
}

TEST(ChannelHealthRules, TheQuantumIsTheChannelsSmallestStep) {
  // Flickering between two adjacent levels of its 0.01 resolution is held within one quantum.
  const RunHealth flicker = channel_health(one_channel("ax", "m/s^2", 30.0, [](double t) {
    return t < 3.0 ? quantised(std::sin(t))
                   : (static_cast<int>(t * 100.0) % 3 == 0 ? -0.57 : -0.56);
  }));
  ASSERT_EQ(flicker.findings.size(), 1u);
  EXPECT_EQ(flicker.findings[0].statement,
            "`ax` is constant at -0.565 m/s^2 from 3 s to 30 s (90 % of its valid samples)");
  // A smooth signal quantised the same way keeps moving by more than one step.
  EXPECT_TRUE(channel_health(one_channel("ax", "m/s^2", 30.0, [](double t) {
                return quantised(std::sin(t));
              })).findings.empty());
}

TEST(ChannelHealthRules, InvalidSamplesAreLeftOutOfEveryChannelRule) {
  // Garbage at invalid rows (the car writes 0 or anything there) is neither held nor out of range.
  RecordedRun run = one_channel("vx", "m/s", 30.0, [](double t) { return 10.0 + std::sin(t); });
  for (std::size_t i = 0; i < 1000; ++i) {
    run.valid[i] = 0;
    run.samples(static_cast<Eigen::Index>(i), 0) = 1e6;
  }
  EXPECT_TRUE(channel_health(run).findings.empty());
}

}  // namespace
}  // namespace dynid::ingest
