// The sampling error of steps (residual/step_timing.hpp): which steps are found, how far the
// interpolation spread them, and the draws of their timing.
#include <gtest/gtest.h>

#include <cmath>
#include <dynid/residual/step_timing.hpp>
#include <limits>
#include <random>
#include <vector>

namespace dynid::residual {
namespace {

constexpr double kSigma = 1.0;

// A slow line with white noise of kSigma, valid everywhere.
Eigen::VectorXd noisy_line(Eigen::Index n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, kSigma);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x(i) = 0.3 * static_cast<double>(i) + normal(rng);
  return x;
}

std::vector<std::uint8_t> all_valid(Eigen::Index n) {
  return std::vector<std::uint8_t>(static_cast<std::size_t>(n), 1);
}

TEST(StepTiming, AStepBetweenTwoSamplesIsFoundWithItsSizeAndPlace) {
  Eigen::VectorXd x = noisy_line(400, 1);
  x.tail(400 - 201).array() += 100.0;  // between samples 200 and 201
  const auto steps = find_steps(x, all_valid(400), kSigma);
  ASSERT_EQ(steps.size(), 1U);
  EXPECT_NEAR(steps[0].centre, 200.5, 1e-12);
  EXPECT_NEAR(steps[0].size, 100.0, 5.0 * kSigma);
  EXPECT_NEAR(steps[0].span, 1.0, 1e-12);
}

TEST(StepTiming, AStepInterpolatedFromASlowerMessageSpansItsFrameInterval) {
  // A 50 Hz message on a 100 Hz grid, its frames half-way between grid samples: the step ramps
  // over the frame interval, three grid increments of 1/4, 1/2 and 1/4 of it.
  Eigen::VectorXd x = noisy_line(400, 2);
  x(201) += 25.0;
  x(202) += 75.0;
  x.tail(400 - 203).array() += 100.0;
  const auto steps = find_steps(x, all_valid(400), kSigma);
  ASSERT_EQ(steps.size(), 1U);
  EXPECT_NEAR(steps[0].centre, 201.5, 0.1);
  EXPECT_NEAR(steps[0].size, 100.0, 5.0 * kSigma);
  EXPECT_NEAR(steps[0].span, 2.0, 0.2);  // the frame interval: two grid intervals
}

TEST(StepTiming, ARampTheSamplesResolveIsNoStep) {
  // A step between two samples, then a ramp of the same size over five grid intervals: the
  // frame interval is the step's one interval, and the ramp's time is in its samples.
  Eigen::VectorXd x = noisy_line(600, 6);
  x.tail(600 - 201).array() += 100.0;
  for (Eigen::Index i = 401; i < 600; ++i)
    x(i) += 20.0 * static_cast<double>(std::min<Eigen::Index>(i - 400, 5));
  const auto steps = find_steps(x, all_valid(600), kSigma);
  ASSERT_EQ(steps.size(), 1U);
  EXPECT_NEAR(steps[0].centre, 200.5, 1e-12);
  EXPECT_NEAR(steps[0].span, 1.0, 1e-12);
}

TEST(StepTiming, NoiseAndSmoothSignalsHoldNoStep) {
  // A curved, fast signal: a 2 Hz sine of 30 units at 100 Hz has second differences of 0.5 unit
  // of a grid interval, above the bound; the local slope takes them out.
  Eigen::VectorXd x = noisy_line(20000, 3);
  for (Eigen::Index i = 0; i < x.size(); ++i)
    x(i) += 30.0 * std::sin(2.0 * M_PI * 2.0 * static_cast<double>(i) / 100.0);
  EXPECT_TRUE(find_steps(x, all_valid(x.size()), kSigma).empty());
}

TEST(StepTiming, OnlyValidSamplesAreLookedAt) {
  Eigen::VectorXd x = noisy_line(400, 4);
  x.tail(400 - 201).array() += 100.0;
  std::vector<std::uint8_t> valid = all_valid(400);
  valid[205] = 0;  // within five increments of the step: not looked at
  EXPECT_TRUE(find_steps(x, valid, kSigma).empty());
  EXPECT_TRUE(find_steps(x, all_valid(399), kSigma).empty());  // flags that do not fit: nothing
  EXPECT_TRUE(find_steps(x, all_valid(400), 0.0).empty());     // no noise measured: nothing
}

TEST(StepTiming, ValuesAtTheEndsOfTheDoubleRangeMakeNoStepWithoutASize) {
  // Increments that overflow: whatever is found has a finite size and span (a draw stays finite).
  Eigen::VectorXd x = noisy_line(400, 7);
  x(200) = std::numeric_limits<double>::max();
  x(201) = -std::numeric_limits<double>::max();
  for (const SampledStep& s : find_steps(x, all_valid(400), kSigma)) {
    EXPECT_TRUE(std::isfinite(s.size));
    EXPECT_TRUE(std::isfinite(s.span));
    EXPECT_TRUE(std::isfinite(s.centre));
  }
  EXPECT_TRUE(find_steps(Eigen::VectorXd::Constant(400, 3.0), all_valid(400), kSigma).empty());
}

TEST(StepTiming, ADrawIsAnImpulseOfTheStepTimesAUniformTimeInItsSpan) {
  const std::vector<SampledStep> steps{{200.25, 100.0, 2.0}};
  std::mt19937_64 rng(5);
  double sum = 0.0;
  double squares = 0.0;
  constexpr int kDraws = 20000;
  for (int d = 0; d < kDraws; ++d) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(400);
    add_step_timing(steps, rng, x);
    EXPECT_NEAR(x(200) * 0.25, x(201) * 0.75, 1e-9);  // split by the centre's place
    const double area = x.sum();
    ASSERT_LE(std::abs(area), 100.0 + 1e-9);  // at most half the span either way
    sum += area;
    squares += area * area;
  }
  EXPECT_NEAR(sum / kDraws, 0.0, 1.0);
  // Uniform over a span of 2 grid intervals: variance (size x span)^2 / 12.
  EXPECT_NEAR(squares / kDraws, 100.0 * 100.0 * 4.0 / 12.0, 0.03 * 100.0 * 100.0 * 4.0 / 12.0);
}

}  // namespace
}  // namespace dynid::residual
