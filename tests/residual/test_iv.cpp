// Instrumental variables (residual/iv_fit.hpp) on synthetic runs whose truth is exact: the
// kinematic model ax = s d_vx + o, its rows built by the product's preprocessing. Errors in
// variables come from white noise on vx, which the preprocessing differentiates into the d_vx
// column; the measured side ax carries its own noise. The true rows are made exact by building
// ax from the preprocessed noise-free d_vx, so every departure from (s, o) is the noise's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/model_fit.hpp"
#include "dynid/signal/butterworth.hpp"
#include "dynid/signal/derivative.hpp"
#include "dynid/signal/zero_phase_filter.hpp"

namespace dynid::residual {
namespace {

constexpr double kRate = 100.0;
constexpr double kScale = 1.02;   // sensor_scale
constexpr double kOffset = 0.15;  // sensor_offset, m/s^2
constexpr Eigen::Index kSamples = 8000;

// The manoeuvre: speed changes of `amplitude` times a few m/s over 3 to 30 s.
double speed(double t, double amplitude) {
  return 15.0 + amplitude * (4.0 * std::sin(0.21 * t) + 1.5 * std::sin(0.9 * t + 0.3) + 0.4 * std::sin(2.3 * t + 1.0));
}

ingest::RecordedRun recorded(const Eigen::VectorXd& vx, const Eigen::VectorXd& ax) {
  ingest::RecordedRun run;
  run.announcement.vehicle = "synthetic";
  run.announcement.run = "r";
  run.announcement.sample_rate_hz = kRate;
  run.announcement.channels = {{"vx", "m/s"}, {"ax", "m/s^2"}};
  run.samples.resize(vx.size(), 2);
  run.samples.col(0) = vx;
  run.samples.col(1) = ax;
  run.valid.assign(static_cast<std::size_t>(vx.size()), 1);
  return run;
}

// One preprocessed run: d_vx from vx with white noise vx_noise, ax = s d_vx(noise-free) + o plus
// white noise ax_noise low-passed as the preprocessing low-passes ax.
std::vector<ingest::PreprocessedSegment> run_with_noise(std::uint64_t seed, double vx_noise, double ax_noise,
                                                        double amplitude = 1.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  Eigen::VectorXd vx(kSamples), clean(kSamples), ax_white(kSamples);
  for (Eigen::Index k = 0; k < kSamples; ++k) {
    clean(k) = speed(static_cast<double>(k) / kRate, amplitude);
    vx(k) = clean(k) + vx_noise * n01(rng);
    ax_white(k) = ax_noise * n01(rng);
  }
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(kSamples);
  std::vector<ingest::PreprocessedSegment> noisy = ingest::preprocess_offline(recorded(vx, ax_white));
  const std::vector<ingest::PreprocessedSegment> exact = ingest::preprocess_offline(recorded(clean, zero));
  for (std::size_t s = 0; s < noisy.size(); ++s) {
    model::ChannelSet& set = noisy[s].channels;
    const Eigen::VectorXd ax = kScale * exact[s].channels["d_vx"] + Eigen::VectorXd::Constant(set.samples(), kOffset) +
                               set["ax"];
    model::ChannelSet rebuilt(set.sample_period(), set.samples());
    rebuilt.add("d_vx", "m/s^2", set["d_vx"]);
    rebuilt.add("ax", "m/s^2", ax);
    noisy[s].channels = rebuilt;
  }
  return noisy;
}

const model::Model& kinematic() {
  static const auto m = model::make_model("kinematic_longitudinal", {});
  return *m;
}

IvFit iv_of(const std::vector<ingest::PreprocessedSegment>& run) {
  return iv_fit(kinematic(), {}, run, kRate, ingest::Preprocessing{}.odmf);
}

ModelFit ls_of(const std::vector<ingest::PreprocessedSegment>& run) {
  FitOptions options;
  options.series = false;
  return fit_model(kinematic(), {}, run, kRate, ingest::Preprocessing{}.odmf, options);
}

TEST(InstrumentLag, IsTheFirstDecimatedLagFromWhichTheFiltersNoiseIsUncorrelated) {
  const ingest::Preprocessing p;  // order 5, DYCARO's cut-off, odmf 8
  const int lag = instrument_lag(p, kRate, 0.01);
  std::printf("lag %d decimated rows (%g s)\n", lag, lag * p.odmf / kRate);
  const signal::Sos sos = signal::butterworth_lowpass(p.butterworth_order, p.cutoff(kRate), kRate);
  Eigen::VectorXd impulse = Eigen::VectorXd::Zero(4001);
  impulse(2000) = 1.0;
  const Eigen::VectorXd h = signal::derivative(signal::zero_phase_filter(sos, impulse), 1.0 / kRate);
  const auto rho = [&](int rows) {
    const Eigen::Index l = static_cast<Eigen::Index>(rows) * p.odmf;
    return h.head(h.size() - l).dot(h.tail(h.size() - l)) / h.squaredNorm();
  };
  EXPECT_GE(lag, 1);
  for (int l = lag; l < lag + 20; ++l) EXPECT_LE(std::abs(rho(l)), 0.01) << "lag " << l;
  // A tighter bound needs a longer lag, a looser one no longer.
  EXPECT_GE(instrument_lag(p, kRate, 0.001), lag);
  EXPECT_LE(instrument_lag(p, kRate, 0.1), lag);
}

// (a) Without any noise IV and LS solve the same exact equations: equal to rounding, both the truth.
TEST(IvFit, OnNoiseFreeRowsEqualsLeastSquaresAndTheTruth) {
  const auto run = run_with_noise(1, 0.0, 0.0);
  const IvFit iv = iv_of(run);
  ASSERT_FALSE(iv.refused) << iv.reason;
  ASSERT_EQ(iv.parameters[0].name, "sensor_scale");
  const ModelFit ls = ls_of(run);
  EXPECT_GT(iv.rows, 900U);
  for (Eigen::Index j = 0; j < 2; ++j) {
    EXPECT_NEAR(iv.value(j), iv.ls_value(j), 1e-10 * (1.0 + std::abs(iv.ls_value(j))));
    EXPECT_NEAR(iv.value(j), ls.estimate.value(j), 1e-9 * (1.0 + std::abs(ls.estimate.value(j))));
  }
  EXPECT_NEAR(iv.value(0), kScale, 1e-9);
  EXPECT_NEAR(iv.value(1), kOffset, 1e-9);
  // Rows weighted by least squares' own 1/sigma: its RMS is about 1 (rounding, scaled), IV's not
  // below.
  EXPECT_GE(iv.residual_rms, iv.ls_residual_rms * (1.0 - 1e-9));
}

// The residuals' RMS on the same rows: least squares minimises it, so IV's is never below it,
// and with noise in a regressor it is above by more than rounding.
TEST(IvFit, ItsResidualIsNeverBelowLeastSquaresOnTheSameRows) {
  const IvFit iv = iv_of(run_with_noise(7, 0.05, 0.05));
  ASSERT_FALSE(iv.refused) << iv.reason;
  EXPECT_GT(iv.ls_residual_rms, 0.0);
  EXPECT_GT(iv.residual_rms, iv.ls_residual_rms * (1.0 + 1e-9));
}

struct Tally {
  int seeds = 0;
  double ls_error = 0.0, iv_error = 0.0, iv_std = 0.0, iv_hac_std = 0.0, ls_std = 0.0;
  double iv_scatter = 0.0;  // std of the IV error over the seeds
  int rejections = 0;
  int rejections_at_10 = 0;  // at 10 %: the level is read better there
  int within_2std = 0;
  int scale_apart = 0;  // seeds where |IV - LS| of the scale exceeds 2 of its difference_std
};

Tally over_seeds(int seeds, double vx_noise, double ax_noise) {
  Tally t;
  for (int s = 1; s <= seeds; ++s) {
    const auto run = run_with_noise(100 + static_cast<std::uint64_t>(s), vx_noise, ax_noise);
    const IvFit iv = iv_of(run);
    const ModelFit ls = ls_of(run);
    EXPECT_FALSE(iv.refused) << iv.reason;
    if (iv.refused) continue;
    ++t.seeds;
    t.ls_error += ls.estimate.value(0) - kScale;
    t.ls_std += ls.estimate.standard_deviation(0);
    t.iv_error += iv.value(0) - kScale;
    t.iv_scatter += (iv.value(0) - kScale) * (iv.value(0) - kScale);
    t.rejections_at_10 += iv.dwh.p_value < 0.1 ? 1 : 0;
    t.iv_std += iv.std(0);
    t.iv_hac_std += iv.hac_std(0);
    t.rejections += iv.dwh.rejects ? 1 : 0;
    t.within_2std += std::abs(iv.value(0) - kScale) <= 2.0 * iv.hac_std(0) ? 1 : 0;
    t.scale_apart += std::abs(iv.value(0) - iv.ls_value(0)) > 2.0 * iv.difference_std(0) ? 1 : 0;
  }
  const double n = std::max(1, t.seeds);
  t.ls_error /= n, t.iv_error /= n, t.iv_std /= n, t.iv_hac_std /= n, t.ls_std /= n;
  t.iv_scatter = std::sqrt(std::max(0.0, t.iv_scatter / n - t.iv_error * t.iv_error) * n / std::max(1.0, n - 1.0));
  std::printf("vx noise %g, ax noise %g, %d seeds: LS scale error %+.5f (std %.5f); IV %+.5f (std %.5f, HAC %.5f), "
              "scatter %.5f, %d within 2 HAC std; DWH rejects at 1 %% in %d, at 10 %% in %d\n",
              vx_noise, ax_noise, t.seeds, t.ls_error, t.ls_std, t.iv_error, t.iv_std, t.iv_hac_std, t.iv_scatter,
              t.within_2std, t.rejections, t.rejections_at_10);
  return t;
}

// (b) White noise on vx sits in the differentiated column: LS is attenuated (by many of its std),
// the DWH test says so, and IV's mean error over the seeds is within its std of one run. The
// mean over 12 seeds has a std of about 0.29 std of one run: a bias of one std fails.
TEST(IvFit, NoiseInTheDifferentiatedChannelBiasesLeastSquaresNotIv) {
  constexpr int kSeeds = 12;
  const Tally t = over_seeds(kSeeds, 0.05, 0.05);
  ASSERT_EQ(t.seeds, kSeeds);
  EXPECT_LT(t.ls_error, -5.0 * t.ls_std) << "the noise must bias LS measurably for the test to mean anything";
  EXPECT_GE(t.rejections, kSeeds - 1);
  EXPECT_LT(std::abs(t.iv_error), t.iv_hac_std);
  EXPECT_LT(std::abs(t.iv_error), std::abs(t.ls_error) / 5.0);
  EXPECT_GE(t.within_2std, kSeeds - 2);
  EXPECT_GE(t.scale_apart, kSeeds - 2) << "the parameter the noise biases is named";
}

// (c) Noise on the measured side only: LS is unbiased, DWH rejects at about its 1 % level (at
// most 3 of 40: the probability of 4 or more is 0.8 % at a true 1 % level, 14 % at 3 %).
TEST(IvFit, WithoutRegressorNoiseTheHausmanTestHoldsItsLevel) {
  constexpr int kSeeds = 40;
  const Tally t = over_seeds(kSeeds, 0.0, 0.05);
  ASSERT_EQ(t.seeds, kSeeds);
  EXPECT_LE(t.rejections, 3);
  EXPECT_LT(std::abs(t.iv_error), t.iv_hac_std);
  // Each seed's |IV - LS| > 2 difference_std at about 5 %: 6 or more of 40 has probability 1 %.
  EXPECT_LE(t.scale_apart, 5);
}

// A regressor that is noise only (constant speed but for the sensor's noise): the lagged rows
// carry nothing of it, and IV is refused with the reason rather than returned.
TEST(IvFit, WeakInstrumentsAreRefusedWithTheReason) {
  const IvFit iv = iv_of(run_with_noise(5, 0.05, 0.05, 0.0));
  EXPECT_TRUE(iv.refused);
  EXPECT_NE(iv.reason.find("weak instruments"), std::string::npos) << iv.reason;
  EXPECT_NE(iv.reason.find("sensor_scale"), std::string::npos) << iv.reason;
  EXPECT_TRUE(std::isnan(iv.value(0)));
  EXPECT_TRUE(std::isnan(iv.residual_rms)) << "a refused fit has no residual to report";
  std::printf("%s\n", iv.reason.c_str());
}

}  // namespace
}  // namespace dynid::residual
