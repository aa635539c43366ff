// SIMEX (residual/simex.hpp) on synthetic raw runs whose truth is known: the kinematic model
// ax = s d_vx + o, the raw channels vx and ax put through the product's preprocessing. Errors
// in variables come from white noise on vx, which the preprocessing differentiates into the d_vx
// column; ax carries its own noise on the measured side. ax is built from the speed's analytic
// derivative, so the noise-free rows are the truth to the central difference's error (~1e-5).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "dynid/error.hpp"
#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/residual/consistency.hpp"
#include "dynid/residual/model_fit.hpp"
#include "dynid/residual/noise_floor.hpp"
#include "dynid/residual/simex.hpp"

namespace dynid::residual {
namespace {

constexpr double kRate = 100.0;
constexpr Eigen::Index kSamples = 8000;  // 80 s
constexpr double kScale = 1.02;          // sensor_scale
constexpr double kOffset = 0.15;         // sensor_offset, m/s^2

// The manoeuvre: speed changes of a few m/s over 3 to 30 s, and its derivative.
double speed(double t) { return 15.0 + 4.0 * std::sin(0.21 * t) + 1.5 * std::sin(0.9 * t + 0.3) + 0.4 * std::sin(2.3 * t + 1.0); }
double acceleration(double t) {
  return 4.0 * 0.21 * std::cos(0.21 * t) + 1.5 * 0.9 * std::cos(0.9 * t + 0.3) + 0.4 * 2.3 * std::cos(2.3 * t + 1.0);
}

// The raw run: vx with white noise vx_noise, ax = s a + o with white noise ax_noise, and a third
// channel (a steering angle) the model does not read, with noise of its own.
ingest::RecordedRun raw_run(std::uint64_t seed, double vx_noise, double ax_noise) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  ingest::RecordedRun run;
  run.announcement.vehicle = "synthetic";
  run.announcement.run = "r";
  run.announcement.sample_rate_hz = kRate;
  run.announcement.channels = {{"vx", "m/s"}, {"ax", "m/s^2"}, {"steer", "rad"}};
  run.samples.resize(kSamples, 3);
  for (Eigen::Index k = 0; k < kSamples; ++k) {
    const double t = static_cast<double>(k) / kRate;
    run.samples(k, 0) = speed(t) + vx_noise * n01(rng);
    run.samples(k, 1) = kScale * acceleration(t) + kOffset + ax_noise * n01(rng);
    run.samples(k, 2) = 0.05 * std::sin(0.7 * t) + 0.01 * n01(rng);
  }
  run.valid.assign(static_cast<std::size_t>(kSamples), 1);
  return run;
}

const model::Model& kinematic() {
  static const auto m = model::make_model("kinematic_longitudinal", {});
  return *m;
}

SimexFit simex_of(const ingest::RecordedRun& run, const std::vector<ChannelNoise>& noise, SimexOptions options = {}) {
  return simex_fit(kinematic(), {}, run, ingest::preprocess_offline(run), noise, options);
}

ModelFit ls_of(const ingest::RecordedRun& run) {
  FitOptions options;
  options.series = false;
  return fit_model(kinematic(), {}, ingest::preprocess_offline(run), kRate, run.announcement.preprocessing.odmf, options);
}

ChannelNoise declared(const std::string& channel, double sigma) { return {channel, sigma, "declared", 0.0}; }

// (a) No noise to simulate, or only on a channel the model does not read: nothing is corrected,
// the value is the estimate table's and the std least squares' HAC one, to rounding.
TEST(Simex, WithoutNoiseReachingTheRowsEqualsLeastSquares) {
  const ingest::RecordedRun run = raw_run(1, 0.0, 0.0);
  const ModelFit ls = ls_of(run);
  const ModelParameters hac =
      hac_parameters(kinematic(), {}, ingest::preprocess_offline(run), kRate, run.announcement.preprocessing.odmf);
  for (const std::vector<ChannelNoise>& noise :
       {std::vector<ChannelNoise>{}, {declared("vx", 0.0), declared("ax", 0.0)}, {declared("steer", 0.02)}}) {
    const SimexFit s = simex_of(run, noise);
    EXPECT_FALSE(s.corrected());
    EXPECT_TRUE(s.contributing.empty());
    ASSERT_EQ(s.parameters[0].name, "sensor_scale");
    for (Eigen::Index j = 0; j < 2; ++j) {
      EXPECT_NEAR(s.value(j), ls.estimate.value(j), 1e-10 * (1.0 + std::abs(ls.estimate.value(j))));
      EXPECT_NEAR(s.std(j), hac.std(j), 1e-10 * hac.std(j));
      EXPECT_EQ(s.monte_carlo_std(j), 0.0);
    }
    EXPECT_NE(s.statement().find("least-squares values stand"), std::string::npos) << s.statement();
  }
  // The noise-free rows are the truth (to the central difference's error).
  EXPECT_NEAR(ls.estimate.value(0), kScale, 1e-4);
  EXPECT_NEAR(ls.estimate.value(1), kOffset, 1e-3);
}

// The same seed gives the same draws, another seed other draws: the correction is reproducible,
// and its Monte Carlo part is what its std says.
TEST(Simex, IsDeterministicPerSeed) {
  const ingest::RecordedRun run = raw_run(2, 0.05, 0.05);
  const std::vector<ChannelNoise> noise{declared("vx", 0.05), declared("ax", 0.05), declared("steer", 0.01)};
  const SimexFit a = simex_of(run, noise);
  const SimexFit b = simex_of(run, noise);
  SimexOptions other;
  other.seed = 2;
  const SimexFit c = simex_of(run, noise, other);
  ASSERT_TRUE(a.corrected());
  EXPECT_EQ(a.contributing, (std::vector<std::string>{"vx", "ax"})) << "steer is not read by the model";
  EXPECT_EQ(a.value(0), b.value(0));
  EXPECT_NE(a.value(0), c.value(0));
  EXPECT_LT(std::abs(a.value(0) - c.value(0)), 4.0 * std::sqrt(2.0) * a.monte_carlo_std(0));
  std::printf("%s\n", a.statement().c_str());
}

struct Tally {
  int seeds = 0;
  double ls_error = 0.0, ls_std = 0.0, simex_error = 0.0, simex_std = 0.0, mc_std = 0.0;
  int within_2std = 0;
};

// (b) White noise on vx, its sigma measured by the product (measure_channel_noise, above the
// cut-off): LS is attenuated by several of its std; SIMEX's mean error over the seeds is within
// a fraction of its std, and its 2-std interval holds the truth.
TEST(Simex, RemovesTheBiasOfNoiseInTheDifferentiatedChannel) {
  constexpr int kSeeds = 8;
  Tally t;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const ingest::RecordedRun run = raw_run(100 + static_cast<std::uint64_t>(seed), 0.05, 0.05);
    const auto segments = ingest::preprocess_offline(run);
    const std::vector<ChannelNoise> noise = measure_channel_noise(run, segments, {});
    const SimexFit s = simex_fit(kinematic(), {}, run, segments, noise, {});
    ASSERT_TRUE(s.corrected());
    ++t.seeds;
    t.ls_error += s.ls_value(0) - kScale;
    t.ls_std += s.ls_hac_std(0);
    t.simex_error += s.value(0) - kScale;
    t.simex_std += s.std(0);
    t.mc_std += s.monte_carlo_std(0);
    t.within_2std += std::abs(s.value(0) - kScale) <= 2.0 * s.std(0) ? 1 : 0;
  }
  const double n = t.seeds;
  t.ls_error /= n, t.ls_std /= n, t.simex_error /= n, t.simex_std /= n, t.mc_std /= n;
  std::printf("vx noise 0.05, ax noise 0.05, %d seeds: LS scale error %+.5f (HAC std %.5f); SIMEX %+.5f (std %.5f, "
              "of it Monte Carlo %.5f), %d within 2 std\n",
              t.seeds, t.ls_error, t.ls_std, t.simex_error, t.simex_std, t.mc_std, t.within_2std);
  EXPECT_LT(t.ls_error, -4.0 * t.ls_std) << "the noise must bias LS measurably for the test to mean anything";
  // The mean over 8 seeds has a std of about 0.35 std of one run: a bias of one std fails.
  EXPECT_LT(std::abs(t.simex_error), t.simex_std);
  EXPECT_LT(std::abs(t.simex_error), std::abs(t.ls_error) / 5.0);
  EXPECT_GE(t.within_2std, kSeeds - 1);
}

// (c) Options out of range and noise that is no sigma are InputError; so is a model whose
// channel the run lacks.
TEST(Simex, RejectsBadInput) {
  const ingest::RecordedRun run = raw_run(3, 0.05, 0.05);
  const std::vector<ChannelNoise> noise{declared("vx", 0.05)};
  SimexOptions one_draw;
  one_draw.draws = 1;
  EXPECT_THROW(simex_of(run, noise, one_draw), InputError);
  SimexOptions one_lambda;
  one_lambda.lambdas = {1.0, 1.0};
  EXPECT_THROW(simex_of(run, noise, one_lambda), InputError);
  SimexOptions negative;
  negative.lambdas = {-0.5, 1.0, 2.0};
  EXPECT_THROW(simex_of(run, noise, negative), InputError);
  SimexOptions none;
  none.lambdas = {};
  EXPECT_THROW(simex_of(run, noise, none), InputError);
  EXPECT_THROW(simex_of(run, {declared("vx", -0.1)}), InputError);
  EXPECT_THROW(simex_of(run, {declared("vx", std::nan(""))}), InputError);
  const auto lateral = model::make_model("lateral_bicycle", {{"a", 1.2}, {"b", 1.5}});
  EXPECT_THROW(simex_fit(*lateral, {}, run, ingest::preprocess_offline(run), noise, {}), InputError);
}

}  // namespace
}  // namespace dynid::residual
