// The real RAV4 log replayed through deploy/profiles/rav4.toml: every frame accounted for,
// chunks contiguous and valid against the run announcement, and the channels equal comma.ai's
// own decodes (reference/*.csv) interpolated at the grid times.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <dynid/error.hpp>

#include "car_test_support.hpp"
#include "dynid/car/candump_source.hpp"
#include "dynid/car/replay.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {
namespace {

struct Series {
  std::vector<double> t;
  std::vector<double> v;
  // Linear interpolation between the bracketing samples (the series covers t).
  double at(double x) const {
    const auto it = std::lower_bound(t.begin(), t.end(), x);
    const auto i = static_cast<std::size_t>(it - t.begin());
    if (it != t.end() && *it == x) return v[i];
    if (i == 0 || i == t.size()) throw std::out_of_range("reference does not cover the grid time");
    return v[i - 1] + (v[i] - v[i - 1]) * ((x - t[i - 1]) / (t[i] - t[i - 1]));
  }
};

// Timestamps of one id on can0 as the log writes them (the grid's clock), read straight from the
// text so that nothing of the pipeline is involved.
std::vector<double> log_times(const std::string& id) {
  std::ifstream in(test::rav4_log());
  std::vector<double> t;
  std::string line;
  const std::string key = " can0 " + id + "#";
  while (std::getline(in, line))
    if (line.find(key) != std::string::npos) t.push_back(std::stod(line.substr(1)));
  return t;
}

// A reference CSV's rows reduced to one value per row by `reduce` over its columns, paired
// with the log times of its frames (comma.ai's timestamps carry more digits than the log's).
template <class Reduce>
Series reference(const std::string& csv, const std::string& id, Reduce reduce) {
  std::ifstream in(test::rav4_data_dir() / "reference" / csv);
  std::string line;
  std::getline(in, line);  // header
  Series s;
  s.t = log_times(id);
  while (std::getline(in, line)) {
    std::vector<double> cols;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cols.push_back(std::stod(cell));
    s.v.push_back(reduce(cols));
  }
  if (s.t.size() != s.v.size()) throw std::runtime_error(csv + ": rows do not match the log's frames");
  return s;
}

struct Replayed {
  VehicleProfile profile;
  std::vector<ingest::Chunk> chunks;
  ReplayProgress progress;
  double origin = 0.0;
  std::vector<ReplayProgress> reports;
};

Replayed replay_rav4(const ReplayOptions& options) {
  Replayed r{load_vehicle_profile(test::profile_path("rav4.toml")), {}, {}, 0.0, {}};
  CarPipeline pipeline(r.profile, "seg40", [&](ingest::Chunk&& c) { r.chunks.push_back(std::move(c)); });
  CandumpSource source(test::rav4_log());
  ReplayOptions o = options;
  o.on_progress = [&](const ReplayProgress& p) { r.reports.push_back(p); };
  r.progress = replay(source, pipeline, o);
  r.origin = pipeline.origin();
  return r;
}

std::size_t column(const VehicleProfile& p, const std::string& channel) {
  for (std::size_t c = 0; c < p.channels.size(); ++c)
    if (p.channels[c].channel == channel) return c;
  throw std::runtime_error("no channel " + channel);
}

// Issue 36, item 3: a channel the profile gives as a constant (a manual car's gear ratio on a
// run in one gear) rides on every frame of the bus: the run's chunks are those of the profile
// without it, row for row and value for value, with one more column holding the constant in
// every valid row (no gap of its own, no message or signal needed).
TEST(CarRav4Replay, AConstantChannelOfTheProfileRidesOnEveryFrame) {
  DYNID_REQUIRE_RAV4_DATA();
  const Replayed base = replay_rav4({});
  std::ifstream in(test::profile_path("rav4.toml"));
  std::stringstream text;
  text << in.rdbuf() << "\n[[channels]]\nname = \"gear_ratio\"\nconstant = 3.5\n";
  const VehicleProfile profile = parse_vehicle_profile(text.str(), test::profile_path("rav4.toml"));
  const std::size_t gear = column(profile, "gear_ratio");
  EXPECT_EQ(*profile.channels[gear].constant, 3.5);
  std::vector<ingest::Chunk> chunks;
  CarPipeline pipeline(profile, "seg40",
                       [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
  CandumpSource source(test::rav4_log());
  replay(source, pipeline);
  ASSERT_EQ(chunks.size(), base.chunks.size());
  std::size_t valid = 0;
  for (std::size_t k = 0; k < chunks.size(); ++k) {
    const ingest::Chunk& a = base.chunks[k];
    const ingest::Chunk& b = chunks[k];
    ASSERT_EQ(b.first_sample_index, a.first_sample_index) << "chunk " << k;
    ASSERT_EQ(b.valid, a.valid) << "chunk " << k;
    for (std::size_t c = 0; c < base.profile.channels.size(); ++c) {
      const auto at = static_cast<Eigen::Index>(column(profile, base.profile.channels[c].channel));
      ASSERT_EQ(b.samples.col(at), a.samples.col(static_cast<Eigen::Index>(c))) << "chunk " << k;
    }
    for (std::size_t row = 0; row < b.valid.size(); ++row)
      if (b.valid[row] != 0) {
        ASSERT_EQ(b.samples(static_cast<Eigen::Index>(row), static_cast<Eigen::Index>(gear)), 3.5);
        ++valid;
      }
  }
  EXPECT_GT(valid, 1000U);
}

TEST(CarRav4Replay, EveryFrameIsAccountedForAndChunksAreContiguous) {
  DYNID_REQUIRE_RAV4_DATA();
  const Replayed r = replay_rav4({});
  const ReplayProgress& p = r.progress;
  EXPECT_EQ(p.frames, 98800U);
  EXPECT_EQ(p.bad, 0U);
  EXPECT_GT(p.other_interface, 20000U);  // the radar bus, ignored by the profile
  EXPECT_EQ(p.frames, p.decoded + p.unknown_id + p.other_interface);
  EXPECT_DOUBLE_EQ(p.fraction, 1.0);
  EXPECT_TRUE(p.done);
  ASSERT_FALSE(r.reports.empty());
  EXPECT_TRUE(r.reports.back().done);
  // 60 s at 50 Hz in 1 s chunks.
  ASSERT_GE(r.chunks.size(), 59U);
  EXPECT_EQ(p.chunks, r.chunks.size());
  const auto announcement = r.profile.announcement("seg40");
  std::uint64_t valid = 0, rows = 0;
  for (std::size_t i = 0; i < r.chunks.size(); ++i) {
    const auto& c = r.chunks[i];
    EXPECT_EQ(c.sequence, i);
    EXPECT_EQ(c.first_sample_index, 50 * i);
    if (i + 1 < r.chunks.size()) {
      EXPECT_EQ(c.samples.rows(), 50);
    }
    EXPECT_NO_THROW(ingest::validate_chunk(c, announcement)) << "chunk " << i;
    for (auto f : c.valid) valid += f;
    rows += c.valid.size();
  }
  EXPECT_EQ(rows, p.rows);
  // Only the first rows (before every message's period is known) are invalid: the recorder's
  // lost single frames are bridged (max_gap_periods = 3 in the profile).
  EXPECT_GE(valid, rows - 4);
}

TEST(CarRav4Replay, ChannelsEqualCommaReferenceDecodesAtGridTimes) {
  DYNID_REQUIRE_RAV4_DATA();
  const Replayed r = replay_rav4({});
  const auto kmh_mean = [](const std::vector<double>& c) { return (c[1] + c[2] + c[3] + c[4]) / 4.0; };
  const Series wheels = reference("wheel_speed.csv", "0AA", kmh_mean);
  const Series angle = reference("steering_angle.csv", "025", [](const std::vector<double>& c) { return c[1]; });
  const std::size_t vx = column(r.profile, "vx");
  const std::size_t steer = column(r.profile, "steer");
  const double deg_per_road_rad = 16.88 * 180.0 / std::numbers::pi;
  std::size_t compared = 0;
  double worst_vx = 0.0, worst_steer = 0.0;
  for (const auto& c : r.chunks) {
    for (Eigen::Index k = 0; k < c.samples.rows(); ++k) {
      if (!c.valid[static_cast<std::size_t>(k)]) continue;
      const double t = r.origin + static_cast<double>(c.first_sample_index + static_cast<std::uint64_t>(k)) / 50.0;
      worst_vx = std::max(worst_vx, std::abs(c.samples(k, static_cast<Eigen::Index>(vx)) - wheels.at(t)));
      worst_steer = std::max(worst_steer,
                             std::abs(c.samples(k, static_cast<Eigen::Index>(steer)) * deg_per_road_rad - angle.at(t)));
      ++compared;
    }
  }
  EXPECT_GT(compared, 2900U);
  EXPECT_LT(worst_vx, 1e-9) << "m/s";
  EXPECT_LT(worst_steer, 1e-9) << "deg at the steering wheel";
}

TEST(CarRav4Replay, ChannelsArePhysicallyConsistent) {
  DYNID_REQUIRE_RAV4_DATA();
  const Replayed r = replay_rav4({});
  // The README: 8 -> 20 m/s in the first 15 s. The accelerometer (specific force) must agree
  // with the wheel-speed derivative in sign and size, grade aside (|grade| < 5 %: 0.5 m/s^2).
  const auto vx = column(r.profile, "vx");
  const auto ax = column(r.profile, "ax");
  const auto ay = column(r.profile, "ay");
  const auto yaw = column(r.profile, "yaw_rate");
  const auto rpm = column(r.profile, "engine_speed");
  std::vector<double> v, a, lat, centripetal, w;
  for (const auto& c : r.chunks)
    for (Eigen::Index k = 0; k < c.samples.rows(); ++k) {
      if (!c.valid[static_cast<std::size_t>(k)]) continue;
      v.push_back(c.samples(k, static_cast<Eigen::Index>(vx)));
      a.push_back(c.samples(k, static_cast<Eigen::Index>(ax)));
      lat.push_back(c.samples(k, static_cast<Eigen::Index>(ay)));
      centripetal.push_back(c.samples(k, static_cast<Eigen::Index>(yaw)) * v.back());
      w.push_back(c.samples(k, static_cast<Eigen::Index>(rpm)));
    }
  ASSERT_GT(v.size(), 2900U);
  const std::size_t n15 = 15 * 50;
  double mean_ax = 0.0;
  for (std::size_t i = 0; i < n15; ++i) mean_ax += a[i] / static_cast<double>(n15);
  const double dv = (v[n15 - 1] - v[0]) / 15.0;
  EXPECT_GT(v[n15 - 1] - v[0], 8.0);
  EXPECT_NEAR(mean_ax, dv, 0.5) << "ax against d(vx)/dt over the first 15 s";
  // ay and yaw_rate * vx (the centripetal acceleration) agree in sign and size (ISO 8855: left
  // positive for both). Compared as 1 s moving means about their averages: the yaw-rate LSB
  // (0.244 deg/s) is worth 0.085 m/s^2 at 20 m/s, as large as the manoeuvre's lateral wiggles.
  const auto smooth = [](const std::vector<double>& x) {
    double mean = 0.0;
    for (double e : x) mean += e / static_cast<double>(x.size());
    std::vector<double> out;
    for (std::size_t i = 0; i + 50 <= x.size(); ++i) {
      double s = 0.0;
      for (std::size_t j = i; j < i + 50; ++j) s += (x[j] - mean) / 50.0;
      out.push_back(s);
    }
    return out;
  };
  const auto y = smooth(lat);
  const auto x = smooth(centripetal);
  double xy = 0.0, xx = 0.0, yy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    xy += x[i] * y[i];
    xx += x[i] * x[i];
    yy += y[i] * y[i];
  }
  EXPECT_GT(xy / std::sqrt(xx * yy), 0.8) << "correlation of ay with yaw_rate * vx";
  EXPECT_GT(xy / xx, 0.7) << "slope of ay on yaw_rate * vx";
  EXPECT_LT(xy / xx, 1.5) << "slope of ay on yaw_rate * vx";
  // Engine speed in rad/s: between idle and 4000 rpm while driving at 8..20 m/s.
  for (double e : w) {
    EXPECT_GT(e, 600.0 * 2.0 * std::numbers::pi / 60.0);
    EXPECT_LT(e, 4000.0 * 2.0 * std::numbers::pi / 60.0);
  }
}

TEST(CarRav4Replay, RealTimeReplayFollowsTheLogClock) {
  DYNID_REQUIRE_RAV4_DATA();
  ReplayOptions o;
  o.speed = 1.0;
  o.max_log_seconds = 1.0;
  o.progress_interval = std::chrono::milliseconds(200);
  const auto start = std::chrono::steady_clock::now();
  const Replayed r = replay_rav4(o);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(wall, 0.95);
  EXPECT_LT(wall, 1.5);
  EXPECT_NEAR(r.progress.log_seconds, 1.0, 0.02);
  EXPECT_GE(r.reports.size(), 4U);  // about every 200 ms, then the final one
  EXPECT_LT(r.progress.fraction, 0.05);
  // Fast mode replays the same second in a fraction of it, with the same rows.
  ReplayOptions fast;
  fast.max_log_seconds = 1.0;
  const auto t0 = std::chrono::steady_clock::now();
  const Replayed f = replay_rav4(fast);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.5);
  EXPECT_EQ(f.progress.rows, r.progress.rows);
  EXPECT_NEAR(static_cast<double>(f.progress.rows), 50.0, 2.0);
}

TEST(CarRav4Replay, BadLinesAreCountedNeverSent) {
  DYNID_REQUIRE_RAV4_DATA();
  test::ScratchDir dir("badlog");
  // The first 2 s of the real log with garbage, a short WHEEL_SPEEDS frame and an unknown id.
  std::ifstream in(test::rav4_log());
  std::ofstream out(dir.path() / "bad.log");
  std::string line;
  int n = 0;
  while (std::getline(in, line) && n++ < 3300) {
    out << line << '\n';
    if (n == 1000) out << "this is not a frame\n(46409.0) can0 0AA#0102\n(46409.0) can0 7FF#00\n";
  }
  out.close();
  const VehicleProfile profile = load_vehicle_profile(test::profile_path("rav4.toml"));
  std::vector<ingest::Chunk> chunks;
  CarPipeline pipeline(profile, "bad", [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
  CandumpSource source(dir.path() / "bad.log");
  const ReplayProgress p = replay(source, pipeline);
  EXPECT_EQ(p.bad, 2U);  // the bad line and the short payload
  EXPECT_EQ(source.errors().size(), 1U);
  EXPECT_NE(source.errors().at(0).find("bad.log:1001:"), std::string::npos) << source.errors().at(0);
  EXPECT_GE(p.unknown_id, 1U);
  ASSERT_FALSE(chunks.empty());
  for (const auto& c : chunks) EXPECT_NO_THROW(ingest::validate_chunk(c, profile.announcement("bad")));
}

}  // namespace
}  // namespace dynid::car
