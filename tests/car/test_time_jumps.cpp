// SourceClock and the Resampler at a jump of the source clock (source_clock.hpp, resampler.hpp
// "Time jumps"): a jump ends the grid piece with one invalid row, no row is made for the time
// between, whatever its size, backwards as forwards; a live bus's long silence ends the piece.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <dynid/error.hpp>

#include "dynid/car/resampler.hpp"
#include "dynid/car/source_clock.hpp"

namespace dynid::car {
namespace {

TEST(SourceClock, JumpsStartPiecesAndCountNothing) {
  SourceClock c({10.0, 1.0});
  EXPECT_FALSE(c.step(100.0));
  EXPECT_FALSE(c.step(105.0));
  EXPECT_FALSE(c.step(104.5));  // a little back: the same piece
  EXPECT_DOUBLE_EQ(c.elapsed(), 5.0);
  EXPECT_TRUE(c.step(1e9));     // forward past the limit
  EXPECT_FALSE(c.step(1e9 + 2.0));
  EXPECT_TRUE(c.step(200.0));   // backward past the limit
  EXPECT_FALSE(c.step(201.0));
  EXPECT_DOUBLE_EQ(c.elapsed(), 5.0 + 2.0 + 1.0);
  EXPECT_EQ(c.jumps(), 2u);
  EXPECT_TRUE(c.silent_at(211.5));
  EXPECT_FALSE(c.silent_at(210.5));
  EXPECT_THROW(SourceClock({0.0, 1.0}), InputError);
  EXPECT_THROW(SourceClock({10.0, std::nan("")}), InputError);
}

struct Rows {
  std::vector<std::uint64_t> index;
  std::vector<bool> valid;
  Resampler::RowSink sink() {
    return [this](std::uint64_t k, std::span<const double>, bool v) {
      index.push_back(k);
      valid.push_back(v);
    };
  }
  std::size_t count_valid() const { return static_cast<std::size_t>(std::count(valid.begin(), valid.end(), true)); }
};

ResamplerConfig two_channels() {
  ResamplerConfig c;
  c.rate_hz = 100.0;
  c.channels = 2;
  return c;
}

// Both channels every 10 ms over [t0, t0 + seconds).
void feed(Resampler& r, double t0, double seconds) {
  for (int k = 0; k < static_cast<int>(seconds * 100.0); ++k) {
    const double t = t0 + k * 0.01;
    r.push(0, t, 1.0);
    r.push(1, t, 2.0);
    r.advance_clock(t);
  }
}

TEST(CarResamplerJumps, AJumpAtAnyScaleCostsOneRowAndTheGridStaysContiguous) {
  for (const double jump : {10.5, 3 * 3600.0, 1e9, -10.5, -2.0, -1e9}) {
    SCOPED_TRACE(jump);
    Rows out;
    Resampler r(two_channels(), out.sink());
    feed(r, 1.7e9, 2.0);
    feed(r, 1.7e9 + 2.0 + jump, 2.0);
    r.finish();
    EXPECT_LE(out.index.size(), 402u);
    EXPECT_GE(out.count_valid(), 390u);
    EXPECT_EQ(r.stats().pieces_ended, 1u);
    for (std::size_t k = 0; k < out.index.size(); ++k) ASSERT_EQ(out.index[k], k);
    // A valid segment never spans the break: an invalid row lies between the pieces.
    const auto first_of_second = std::find(out.valid.begin() + 150, out.valid.end(), false);
    EXPECT_NE(first_of_second, out.valid.end());
  }
}

TEST(CarResamplerJumps, AGapShorterThanTheLimitStaysAGapOfInvalidRows) {
  Rows out;
  Resampler r(two_channels(), out.sink());
  feed(r, 1.7e9, 2.0);
  feed(r, 1.7e9 + 2.0 + 5.0, 2.0);  // 5 s < max_time_jump (10 s)
  r.finish();
  EXPECT_EQ(r.stats().pieces_ended, 0u);
  EXPECT_NEAR(static_cast<double>(out.index.size()), 900.0, 3.0);
}

TEST(CarResamplerJumps, ALongSilenceOfALiveBusEndsThePieceAndEmitsNothingMore) {
  Rows out;
  Resampler r(two_channels(), out.sink());
  feed(r, 1.7e9, 2.0);
  for (double t = 1.7e9 + 2.0; t < 1.7e9 + 3600.0; t += 0.1) r.idle(t);  // an hour of silence
  const std::size_t after_silence = out.index.size();
  EXPECT_LE(after_silence, 200u + 1000u + 1u);  // at most max_time_jump of invalid rows
  EXPECT_EQ(r.stats().pieces_ended, 1u);
  feed(r, 1.7e9 + 3600.0, 2.0);
  r.finish();
  EXPECT_LE(out.index.size(), after_silence + 201u);
  EXPECT_GE(out.count_valid(), 390u);
}

}  // namespace
}  // namespace dynid::car
