// Resampler and ChunkBuilder on synthetic signals: linear signals come out exact, gaps come out
// as invalid rows (never interpolated), rows leave within the latency bound, chunks are
// contiguous and sealed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <dynid/error.hpp>

#include "dynid/car/chunk_builder.hpp"
#include "dynid/car/resampler.hpp"

namespace dynid::car {
namespace {

struct Row {
  std::uint64_t index;
  std::vector<double> values;
  bool valid;
};

struct Collector {
  std::vector<Row> rows;
  Resampler::RowSink sink() {
    return [this](std::uint64_t k, std::span<const double> v, bool valid) {
      rows.push_back({k, std::vector<double>(v.begin(), v.end()), valid});
    };
  }
};

ResamplerConfig config(std::size_t channels, double rate, double origin) {
  ResamplerConfig c;
  c.rate_hz = rate;
  c.channels = channels;
  c.origin = origin;
  return c;
}

// Sample times every `period` with uniform jitter of +-jitter, from t0 to t1.
std::vector<double> jittered_times(double t0, double t1, double period, double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  std::vector<double> t;
  for (double x = t0; x < t1; x += period) t.push_back(x + u(rng));
  return t;
}

double line0(double t) { return 3.0 + 2.5 * t; }
double line1(double t) { return -1.0 - 0.75 * t; }

TEST(CarResampler, LinearSignalsAreReproducedExactlyAtEveryGridTime) {
  Collector out;
  const double origin = 1000.0;  // a log clock far from zero, as real ones are
  Resampler r(config(2, 50.0, origin), out.sink());
  // Two channels at different rates with jitter, interleaved in time order as a bus does.
  const auto t0 = jittered_times(origin - 0.2, origin + 10.0, 0.012, 0.002, 1);
  const auto t1 = jittered_times(origin - 0.2, origin + 10.0, 0.024, 0.004, 2);
  std::size_t i = 0, j = 0;
  while (i < t0.size() || j < t1.size()) {
    if (j == t1.size() || (i < t0.size() && t0[i] < t1[j])) {
      r.push(0, t0[i], line0(t0[i]));
      ++i;
    } else {
      r.push(1, t1[j], line1(t1[j]));
      ++j;
    }
  }
  r.finish();
  ASSERT_GT(out.rows.size(), 490U);
  std::size_t valid = 0;
  for (std::size_t k = 0; k < out.rows.size(); ++k) {
    const Row& row = out.rows[k];
    ASSERT_EQ(row.index, k);
    if (!row.valid) continue;
    ++valid;
    const double t = origin + static_cast<double>(k) / 50.0;
    EXPECT_NEAR(row.values[0], line0(t), 1e-9 * std::abs(line0(t))) << "row " << k;
    EXPECT_NEAR(row.values[1], line1(t), 1e-9 * std::abs(line1(t))) << "row " << k;
  }
  // Samples started before the origin, so after the few startup intervals every row is valid.
  EXPECT_EQ(valid, out.rows.size());
  EXPECT_EQ(r.stats().invalid_rows, 0U);
}

TEST(CarResampler, AGapBecomesInvalidRowsNotAnInterpolation) {
  Collector out;
  Resampler r(config(2, 100.0, 0.0), out.sink());
  // Channel 0 at 10 ms throughout; channel 1 at 10 ms but silent between 1.0 and 1.3 s.
  for (int n = -5; n <= 300; ++n) {
    const double t = 0.01 * n + 0.003;
    r.push(0, t, line0(t));
    if (t < 1.0 || t > 1.3) r.push(1, t, line1(t));
  }
  r.finish();
  // The last sample before the gap is 0.993, the first after 1.303: grid times strictly between
  // are not bracketed within 2.5 periods, so rows 100..130 are invalid and carry zeros.
  for (const Row& row : out.rows) {
    const double t = 0.01 * static_cast<double>(row.index);
    const bool in_gap = t > 0.993 && t < 1.303;
    EXPECT_EQ(row.valid, !in_gap) << "row " << row.index;
    if (in_gap) {
      EXPECT_EQ(row.values[0], 0.0);
      EXPECT_EQ(row.values[1], 0.0);
    } else {
      EXPECT_NEAR(row.values[1], line1(t), 1e-12);
    }
  }
  EXPECT_EQ(r.stats().invalid_rows, 31U);
  EXPECT_EQ(r.stats().missing_by_channel[0], 0U);
  EXPECT_EQ(r.stats().missing_by_channel[1], 31U);
}

TEST(CarResampler, JitterWithinTheWindowIsBridgedButTwoMissedFramesAreAGap) {
  Collector out;
  Resampler r(config(1, 100.0, 0.0), out.sink());
  // 10 ms frames; one interval of 20 ms (one frame lost, 2 periods <= 2.5) and one of 30 ms.
  std::vector<double> times;
  for (int n = -5; n <= 50; ++n) times.push_back(0.01 * n + 0.005);
  std::erase_if(times, [](double t) { return std::abs(t - 0.205) < 1e-9; });                   // lost 1
  std::erase_if(times, [](double t) { return std::abs(t - 0.305) < 1e-9 || std::abs(t - 0.315) < 1e-9; });  // lost 2
  for (double t : times) r.push(0, t, line0(t));
  r.finish();
  for (const Row& row : out.rows) {
    const double t = 0.01 * static_cast<double>(row.index);
    const bool gap = t > 0.295 && t < 0.325;
    EXPECT_EQ(row.valid, !gap) << "row " << row.index;
  }
}

TEST(CarResampler, NothingBeforeTheFirstSampleOrPastTheLast) {
  Collector out;
  Resampler r(config(1, 100.0, 0.0), out.sink());
  for (int n = 0; n <= 20; ++n) r.push(0, 0.053 + 0.01 * n, 1.0);
  r.finish();
  ASSERT_EQ(out.rows.size(), 26U);  // rows 0..25: up to the last sample at 0.253
  for (const Row& row : out.rows) {
    // Before the first sample nothing is known; the first kMinIntervals - 1 intervals have no
    // period estimate yet, so they are not bridged either (0.053 .. 0.073).
    const bool valid = row.index >= 8;
    EXPECT_EQ(row.valid, valid) << "row " << row.index;
  }
}

TEST(CarResampler, ASilentChannelDoesNotHoldRowsBack) {
  Collector out;
  Resampler r(config(2, 100.0, 0.0), out.sink());
  for (int n = 0; n <= 20; ++n) {
    r.push(0, 0.01 * n, 1.0);
    r.push(1, 0.01 * n + 0.001, 2.0);
  }
  const std::size_t before = out.rows.size();
  EXPECT_GE(before, 19U);
  // Channel 1 falls silent; channel 0 goes on. Once the clock is past channel 1's last sample +
  // 2.5 x 10 ms, its rows are decided (invalid) and emitted without waiting for max_latency.
  for (int n = 21; n <= 40; ++n) r.push(0, 0.01 * n, 1.0);
  EXPECT_GE(out.rows.size(), 39U);
  EXPECT_FALSE(out.rows.back().valid);
  // A channel that never sent anything is released by the latency bound (1 s of source clock).
  Collector out2;
  Resampler r2(config(2, 100.0, 0.0), out2.sink());
  for (int n = 0; n <= 150; ++n) r2.push(0, 0.01 * n, 1.0);
  EXPECT_NEAR(static_cast<double>(out2.rows.size()), 50.0, 1.0);  // rows up to clock - 1 s
  EXPECT_FALSE(out2.rows.front().valid);
}

TEST(CarResampler, BackwardsAndDuplicateTimesAreDroppedAndCounted) {
  Collector out;
  Resampler r(config(1, 100.0, 0.0), out.sink());
  for (int n = 0; n <= 10; ++n) r.push(0, 0.01 * n, line0(0.01 * n));
  r.push(0, 0.1, 999.0);   // duplicate time
  r.push(0, 0.05, 999.0);  // backwards
  for (int n = 11; n <= 20; ++n) r.push(0, 0.01 * n, line0(0.01 * n));
  r.finish();
  EXPECT_EQ(r.stats().out_of_order, 2U);
  for (const Row& row : out.rows)
    if (row.valid) {
      EXPECT_NEAR(row.values[0], line0(0.01 * static_cast<double>(row.index)), 1e-12);
    }
}

TEST(CarResampler, RejectsBadConfiguration) {
  Collector out;
  EXPECT_THROW(Resampler(config(1, 0.0, 0.0), out.sink()), InputError);
  EXPECT_THROW(Resampler(config(0, 10.0, 0.0), out.sink()), InputError);
  auto c = config(2, 10.0, 0.0);
  c.max_gap = {0.1};
  EXPECT_THROW(Resampler(c, out.sink()), InputError);
  c.max_gap_periods = 0.5;
  c.max_gap.clear();
  EXPECT_THROW(Resampler(c, out.sink()), InputError);
}

double quadratic(double t) { return 0.4 - 1.5 * (t - 1000.0) + 2.0 * (t - 1000.0) * (t - 1000.0); }

ResamplerConfig cubic_config(std::size_t channels, double rate, double origin) {
  ResamplerConfig c = config(channels, rate, origin);
  c.interpolation.assign(channels, Interpolation::kCubic);
  return c;
}

// Pushes a channel's jittered samples of f in one call per `batch` samples, then finishes.
std::vector<Row> resample_cubic(const std::vector<double>& times, double (*f)(double), std::size_t batch) {
  Collector out;
  Resampler r(cubic_config(1, 100.0, 1000.0), out.sink());
  for (std::size_t i = 0; i < times.size(); i += batch)
    for (std::size_t j = i; j < std::min(times.size(), i + batch); ++j) r.push(0, times[j], f(times[j]));
  r.finish();
  return out.rows;
}

TEST(CarResampler, CubicChannelsReproduceQuadraticsExactlyBetweenJitteredFrames) {
  // The parabolas through three frames are the quadratic itself, whatever the spacing, so the
  // Hermite cubic between two frames is too; linear interpolation misses by the curvature.
  const auto times = jittered_times(999.8, 1005.0, 0.02, 0.004, 3);
  const std::vector<Row> rows = resample_cubic(times, quadratic, 1);
  ASSERT_GT(rows.size(), 490U);
  std::size_t valid = 0;
  for (const Row& row : rows) {
    const double t = 1000.0 + static_cast<double>(row.index) / 100.0;
    // After the second-to-last frame the end slope is the secant's (no successor): not exact.
    if (!row.valid || t > times[times.size() - 2]) continue;
    ++valid;
    ASSERT_NEAR(row.values[0], quadratic(t), 1e-9) << "row " << row.index;
  }
  EXPECT_GT(valid, 490U);
  Collector linear;
  Resampler r(config(1, 100.0, 1000.0), linear.sink());
  for (double t : times) r.push(0, t, quadratic(t));
  r.finish();
  double worst = 0.0;
  for (const Row& row : linear.rows)
    if (row.valid) worst = std::max(worst, std::abs(row.values[0] - quadratic(1000.0 + static_cast<double>(row.index) / 100.0)));
  EXPECT_GT(worst, 1e-5);  // 2 x (0.012 s)^2 / 4 where a frame is late
}

TEST(CarResampler, ACubicSineLosesFarLessThanALinearOneBetweenFrames) {
  // A 1 Hz sine sent at 50 Hz, a quarter period off a 100 Hz grid (as bench/trace's inertial
  // message): linear interpolation misses by up to u (1 - u) (w T)^2 / 2 = 0.15 % of the
  // amplitude at u = 1/4, the cubic by a third-order term, (w T)^3 / 16 at most: 1.2e-4.
  auto sine = [](double t) { return std::sin(2.0 * 3.141592653589793 * (t - 1000.0)); };
  std::vector<double> times;
  for (int n = -10; n < 500; ++n) times.push_back(1000.005 + 0.02 * n);
  auto worst_error = [&](ResamplerConfig c) {
    Collector out;
    Resampler r(c, out.sink());
    for (double t : times) r.push(0, t, sine(t));
    r.finish();
    double worst = 0.0;
    for (const Row& row : out.rows) {
      const double t = 1000.0 + static_cast<double>(row.index) / 100.0;
      if (row.valid && t < times[times.size() - 2]) worst = std::max(worst, std::abs(row.values[0] - sine(t)));
    }
    return worst;
  };
  const double linear = worst_error(config(1, 100.0, 1000.0));
  const double cubic = worst_error(cubic_config(1, 100.0, 1000.0));
  EXPECT_GT(linear, 1e-3);
  EXPECT_LT(cubic, 1.5e-4);
  EXPECT_LT(cubic, linear / 8.0);
}

TEST(CarResampler, CubicRowsDoNotDependOnHowTheFramesAreBatchedOrOnAnIdleClock) {
  const auto times = jittered_times(999.9, 1003.0, 0.02, 0.003, 4);
  const std::vector<Row> one = resample_cubic(times, quadratic, 1);
  const std::vector<Row> many = resample_cubic(times, quadratic, 37);
  ASSERT_EQ(one.size(), many.size());
  for (std::size_t k = 0; k < one.size(); ++k) {
    EXPECT_EQ(one[k].valid, many[k].valid);
    EXPECT_EQ(one[k].values, many[k].values) << "row " << k;
  }
  // A live loop's idle clock running ahead of the frames (a frame in flight) does not decide a
  // cubic row before its next frame: the row waits for the frames' own clock. 35 ms ahead: less
  // than the 2.5 periods after which a linear channel's next frame is given up, more than the
  // 1.5 periods a cubic row's successor is due after them (judged by the idle clock, this row
  // would be emitted with the secant's slope).
  Collector live;
  Resampler r(cubic_config(1, 100.0, 1000.0), live.sink());
  for (double t : times) {
    r.idle(t + 0.035);
    r.push(0, t, quadratic(t));
  }
  r.finish();
  ASSERT_EQ(live.rows.size(), one.size());
  for (std::size_t k = 0; k < one.size(); ++k) EXPECT_EQ(live.rows[k].values, one[k].values) << "row " << k;
}

TEST(CarResampler, ACubicChannelWaitsForTheFrameAfterTheBracketAndBridgesNoGap) {
  Collector out;
  Resampler r(cubic_config(1, 100.0, 0.0), out.sink());
  for (int n = 0; n <= 10; ++n) r.push(0, 0.01 * n + 0.005, line0(0.01 * n + 0.005));
  // Row 10 (t = 0.1) lies between the frames at 0.095 and 0.105: it needs the one after 0.105.
  ASSERT_EQ(out.rows.size(), 10U);
  r.push(0, 0.115, line0(0.115));
  EXPECT_EQ(out.rows.size(), 11U);
  // A gap: the frames around it are not used as neighbours, and nothing is bridged across it.
  for (int n = 40; n <= 60; ++n) r.push(0, 0.01 * n + 0.005, line0(0.01 * n + 0.005));
  r.finish();
  for (const Row& row : out.rows) {
    const double t = 0.01 * static_cast<double>(row.index);
    if (t > 0.115 && t < 0.405) {
      EXPECT_FALSE(row.valid) << "row " << row.index;
    } else if (row.valid) {
      EXPECT_NEAR(row.values[0], line0(t), 1e-12) << "row " << row.index;
    }
  }
  auto c = cubic_config(2, 10.0, 0.0);
  c.interpolation.pop_back();
  EXPECT_THROW(Resampler(c, out.sink()), InputError);
}

TEST(CarChunkBuilder, ChunksAreContiguousSealedAndSelfLocating) {
  std::vector<ingest::Chunk> chunks;
  ChunkBuilder b("veh", "run", 2, 4, [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); }, 7);
  for (std::uint64_t k = 3; k < 14; ++k) {
    const double v[2] = {static_cast<double>(k), -static_cast<double>(k)};
    b.add_row(k, v, k != 5);
  }
  b.flush();
  ASSERT_EQ(chunks.size(), 3U);
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const auto& c = chunks[i];
    EXPECT_EQ(c.sequence, 7 + i);
    EXPECT_EQ(c.first_sample_index, 3 + 4 * i);
    EXPECT_EQ(c.vehicle, "veh");
    EXPECT_EQ(c.run, "run");
    EXPECT_EQ(c.checksum, c.compute_checksum());
    EXPECT_EQ(static_cast<std::size_t>(c.samples.rows()), c.valid.size());
    for (Eigen::Index r = 0; r < c.samples.rows(); ++r)
      EXPECT_EQ(c.samples(r, 0), static_cast<double>(c.first_sample_index) + static_cast<double>(r));
  }
  EXPECT_EQ(chunks[2].samples.rows(), 3);  // the final partial chunk
  EXPECT_EQ(chunks[0].valid, (std::vector<std::uint8_t>{1, 1, 0, 1}));
  EXPECT_EQ(b.next_sequence(), 10U);
  const double v[2] = {0.0, 0.0};
  EXPECT_THROW(b.add_row(20, v, true), std::logic_error);  // a hole in the grid is a bug
}

}  // namespace
}  // namespace dynid::car
