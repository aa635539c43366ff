// Offline zero-phase filter: |H|^2 without phase shift on sinusoids, scipy's sosfiltfilt to
// rounding error (edges included), rejected inputs.
#include "dynid/signal/zero_phase_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>

#include "dynid/error.hpp"
#include "dynid/signal/butterworth.hpp"
#include "scipy_reference.hpp"
#include "test_support.hpp"

namespace dynid::signal {
namespace {

Eigen::VectorXd sine(Eigen::Index n, double f, double fs, double phase) {
  Eigen::VectorXd x(n);
  for (Eigen::Index k = 0; k < n; ++k)
    x(k) = std::sin(2.0 * std::numbers::pi * f * static_cast<double>(k) / fs + phase);
  return x;
}

TEST(ZeroPhaseFilter, SinusoidGetsSquaredGainAndNoPhaseShift) {
  const double fs = 200.0;
  const double fc = 10.0;
  const Eigen::Index n = 20000;
  for (int order : {1, 2, 5, 8}) {
    const Sos sos = butterworth_lowpass(order, fc, fs);
    for (double f : {1.0, 7.0, 10.0, 13.0, 25.0}) {
      const double gain = std::pow(test::butterworth_magnitude(order, f, fc, fs), 2);
      const Eigen::VectorXd x = sine(n, f, fs, 0.4);
      const Eigen::VectorXd y = zero_phase_filter(sos, x);
      // In the middle the edge transients have long decayed: y = |H|^2 x, sample by sample,
      // which also says the phase shift is zero.
      const Eigen::VectorXd middle = y.segment(n / 4, n / 2) - gain * x.segment(n / 4, n / 2);
      EXPECT_LT(middle.cwiseAbs().maxCoeff(), 1e-9) << "order " << order << ", f " << f;
    }
  }
}

TEST(ZeroPhaseFilter, ConstantSignalPassesUnchanged) {
  // Steady-state initial conditions: no start-up transient at all.
  const Sos sos = butterworth_lowpass(6, 3.125, 650.0);
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(500, 7.25);
  EXPECT_LT((zero_phase_filter(sos, x) - x).cwiseAbs().maxCoeff(), 1e-9);
}

struct Case {
  int order;
  double cutoff_hz;
  double rate_hz;
  Eigen::Index rows;
};

TEST(ZeroPhaseFilter, MatchesScipySosfiltfilt) {
  const Case cases[] = {{1, 10.0, 100.0, 400},   {2, 3.125, 650.0, 3000}, {3, 45.0, 100.0, 300},
                        {4, 6.125, 650.0, 2000}, {5, 3.125, 650.0, 5000}, {6, 25.0, 100.0, 500},
                        {7, 100.0, 1000.0, 800}, {8, 6.125, 650.0, 4000}, {8, 40.0, 100.0, 200}};
  for (const Case& c : cases) {
    const Eigen::MatrixXd x = test::test_signal(c.rows, 3, 11u + static_cast<unsigned>(c.order));
    std::string why;
    const auto ref = test::run_scipy(c.order, c.cutoff_hz, c.rate_hz, &x, why);
    ASSERT_TRUE(ref) << why << " (deploy/setup.sh installs python3-scipy)";
    ASSERT_TRUE(ref->error.empty()) << ref->error;
    const Eigen::MatrixXd y =
        zero_phase_filter(butterworth_lowpass(c.order, c.cutoff_hz, c.rate_hz), x);
    ASSERT_EQ(y.rows(), ref->filtered.rows());
    ASSERT_EQ(y.cols(), ref->filtered.cols());
    const double scale = x.cwiseAbs().maxCoeff();
    EXPECT_LT((y - ref->filtered).cwiseAbs().maxCoeff(), 1e-10 * scale)
        << "order " << c.order << ", fc " << c.cutoff_hz << ", fs " << c.rate_hz;
  }
}

TEST(ZeroPhaseFilter, ShortestSignalAgreesWithScipyOnTheLimit) {
  for (int order : {3, 4}) {
    const Sos sos = butterworth_lowpass(order, 10.0, 100.0);
    const Eigen::Index padlen = zero_phase_padlen(sos);
    const Eigen::MatrixXd too_short = test::test_signal(padlen, 1, 5u);
    const Eigen::MatrixXd just_enough = test::test_signal(padlen + 1, 1, 6u);
    std::string why;
    const auto ref_short = test::run_scipy(order, 10.0, 100.0, &too_short, why);
    const auto ref_enough = test::run_scipy(order, 10.0, 100.0, &just_enough, why);
    ASSERT_TRUE(ref_short && ref_enough) << why << " (deploy/setup.sh installs python3-scipy)";
    EXPECT_FALSE(ref_short->error.empty()) << "scipy accepted " << padlen << " samples";
    test::expect_input_error([&] { (void)zero_phase_filter(sos, too_short); },
                             std::to_string(padlen) + " samples");
    ASSERT_TRUE(ref_enough->error.empty()) << ref_enough->error;
    EXPECT_LT((zero_phase_filter(sos, just_enough) - ref_enough->filtered).cwiseAbs().maxCoeff(),
              1e-10 * just_enough.cwiseAbs().maxCoeff());
  }
}

TEST(ZeroPhaseFilter, PadlenIsScipysRule) {
  // 3 * (2 * sections + 1), one tap less when a first-order section is present (odd orders).
  EXPECT_EQ(zero_phase_padlen(butterworth_lowpass(1, 10.0, 100.0)), 6);
  EXPECT_EQ(zero_phase_padlen(butterworth_lowpass(2, 10.0, 100.0)), 9);
  EXPECT_EQ(zero_phase_padlen(butterworth_lowpass(5, 10.0, 100.0)), 18);
  EXPECT_EQ(zero_phase_padlen(butterworth_lowpass(8, 10.0, 100.0)), 27);
}

TEST(ZeroPhaseFilter, RejectsNonFiniteSamplesNamingChannelAndSample) {
  const Sos sos = butterworth_lowpass(4, 10.0, 100.0);
  Eigen::MatrixXd x = test::test_signal(200, 3, 1u);
  x(123, 2) = std::numeric_limits<double>::quiet_NaN();
  test::expect_input_error([&] { (void)zero_phase_filter(sos, x); },
                           "channel 2, sample 123 is NaN");
  x(123, 2) = 0.0;
  x(7, 0) = -std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)zero_phase_filter(sos, x), InputError);
}

// The edge reach against its definition, computed here another way: the offline filter's response
// to an impulse far from both ends (so that the edges play no part), its mass beyond d on one side.
TEST(ZeroPhaseFilter, EdgeReachLeavesAtMostTheShareBeyondAnEnd) {
  for (const auto& [order, cutoff, share] :
       {std::tuple{5, 5.0, 0.01}, std::tuple{2, 5.0, 0.01}, std::tuple{5, 2.0, 0.01}, std::tuple{5, 5.0, 0.001}}) {
    const Sos sos = butterworth_lowpass(order, cutoff, 100.0);
    const Eigen::Index half = 2000;
    Eigen::VectorXd impulse = Eigen::VectorXd::Zero(2 * half + 1);
    impulse(half) = 1.0;
    const Eigen::VectorXd g = zero_phase_filter(sos, impulse).col(0).cwiseAbs();
    const auto beyond = [&](Eigen::Index d) { return g.tail(half - d).sum() / g.sum(); };
    const Eigen::Index d = zero_phase_edge_reach(sos, share);
    SCOPED_TRACE("order " + std::to_string(order) + ", cut-off " + std::to_string(cutoff) + " Hz");
    ASSERT_GT(d, 0);
    EXPECT_LE(beyond(d), share * (1.0 + 1e-9));
    EXPECT_GT(beyond(d - 1), share);
  }
  // A lower cut-off reaches further; so does a smaller share. The documented default: 35 samples
  // (5th order, 5 Hz at 100 Hz, 1 %; scipy's sosfiltfilt of an impulse gives the same).
  const Sos sos = butterworth_lowpass(5, 5.0, 100.0);
  EXPECT_EQ(zero_phase_edge_reach(sos, 0.01), 35);
  EXPECT_GT(zero_phase_edge_reach(butterworth_lowpass(5, 2.0, 100.0), 0.01), zero_phase_edge_reach(sos, 0.01));
  EXPECT_GT(zero_phase_edge_reach(sos, 0.001), zero_phase_edge_reach(sos, 0.01));
  test::expect_input_error([&] { (void)zero_phase_edge_reach(sos, 0.0); }, "outside share");
  // A cut-off of 1e-6 of the sample rate (an announcement may carry one): refused, not searched
  // over tens of millions of samples.
  test::expect_input_error([&] { (void)zero_phase_edge_reach(butterworth_lowpass(5, 1e-4, 100.0), 0.01); },
                           "has not decayed");
  test::expect_input_error([&] { (void)zero_phase_edge_reach(sos, 0.5); }, "outside share");
}

}  // namespace
}  // namespace dynid::signal
