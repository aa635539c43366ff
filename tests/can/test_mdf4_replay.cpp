// Must-show 2 of ASAM MDF4: the two splits of CANedge recording 00000164 (shared data
// mdf4-canedge/raw) replay as one run through dynid-car's replay source (car/log_source.hpp),
// in time order, with no gap at the join. Skips without the shared data.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <vector>

#include "dynid/can/mdf4_bus.hpp"
#include "dynid/car/log_source.hpp"

namespace dynid::car {
namespace {

const std::filesystem::path kRaw =
    std::filesystem::path(DYNID_SHARED_DATA) / "mdf4-canedge" / "raw";
const std::filesystem::path kSplit1 = kRaw / "3BA199E2_00000164_00000001-60FE3F04.MF4";
const std::filesystem::path kSplit2 = kRaw / "3BA199E2_00000164_00000002-60FE415D.MF4";

std::vector<can::Frame> replay_all(LogSource& source) {
  std::vector<can::Frame> out;
  can::Frame f;
  while (source.next(f, std::chrono::milliseconds(0)) == NextStatus::Frame) out.push_back(f);
  return out;
}

std::vector<can::Frame> read_file(const std::filesystem::path& path) {
  can::Mdf4BusReader reader(path);
  std::vector<can::Frame> out;
  can::Frame f;
  while (reader.next(f)) out.push_back(f);
  return out;
}

TEST(Mdf4Replay, TheTwoSplitsOfARecordingReplayAsOneRunWithoutAGapAtTheJoin) {
  if (!std::filesystem::is_directory(kRaw))
    GTEST_SKIP() << kRaw << " is absent (set -DDYNID_SHARED_DATA)";
  const auto split1 = read_file(kSplit1), split2 = read_file(kSplit2);
  const std::size_t n1 = split1.size(), n2 = split2.size();
  ASSERT_GT(n1, 0U);
  ASSERT_GT(n2, 0U);
  // the join: the last frame of split 1 and the first of split 2
  const double last1 = split1.back().timestamp, first2 = split2.front().timestamp;
  EXPECT_LT(last1, first2);
  // given in either order, the files are merged by time
  for (const auto& order : {std::vector{kSplit1, kSplit2}, std::vector{kSplit2, kSplit1}}) {
    LogSource source(order);
    const auto frames = replay_all(source);
    EXPECT_EQ(source.bad_input(), 0U);
    EXPECT_EQ(source.fraction_done(), 1.0);
    ASSERT_EQ(frames.size(), n1 + n2);
    for (std::size_t i = 0; i < frames.size(); ++i) {  // split 1, then split 2, frame for frame
      const can::Frame& want = i < n1 ? split1[i] : split2[i - n1];
      ASSERT_TRUE(frames[i].timestamp == want.timestamp && frames[i].id == want.id &&
                  frames[i].data == want.data &&
                  frames[i].interface_name() == want.interface_name())
          << "frame " << i;
    }
    std::vector<double> steps;
    for (std::size_t i = 1; i < frames.size(); ++i) {
      ASSERT_LE(frames[i - 1].timestamp, frames[i].timestamp)
          << "frame " << i << " goes back in time";
      steps.push_back(frames[i].timestamp - frames[i - 1].timestamp);
    }
    std::vector<double> sorted = steps;
    std::nth_element(sorted.begin(),
                     sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    std::sort(sorted.begin(), sorted.end());
    const double p99 = sorted[sorted.size() * 99 / 100];
    const double gap = first2 - last1;
    // no gap: the step at the join is one of the log's ordinary steps between frames
    EXPECT_LE(gap, p99) << "join gap " << gap << " s, 99th percentile of the steps " << p99 << " s";
    std::cout << source.name() << ": " << frames.size() << " frames (" << n1 << " + " << n2
              << "), last of split 1 " << std::fixed << last1 << ", first of split 2 " << first2
              << ": join gap " << gap * 1e3 << " ms; median step " << median * 1e3
              << " ms, 99th percentile " << p99 * 1e3 << " ms\n";
  }
}

}  // namespace
}  // namespace dynid::car
