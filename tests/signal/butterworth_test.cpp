// Butterworth design: analytic magnitude response, scipy's coefficients, rejected designs.
#include "dynid/signal/butterworth.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "dynid/error.hpp"
#include "scipy_reference.hpp"
#include "test_support.hpp"

namespace dynid::signal {
namespace {

struct Design {
  double cutoff_hz;
  double rate_hz;
};

// DYCARO's settings (venture §4.3: 6.125 and 3.125 Hz, about 650 Hz), a mid-band and a
// near-Nyquist cut-off, and the DYCARO rule for a decimation by 4 at 1 kHz.
const std::vector<Design> kDesigns = {
    {3.125, 650.0}, {6.125, 650.0}, {10.0, 100.0}, {45.0, 100.0}, {100.0, 1000.0}};

TEST(Butterworth, DcGainIsOneAndCutoffIsMinus3dB) {
  for (int order = 1; order <= 8; ++order) {
    for (const Design& d : kDesigns) {
      const Eigen::MatrixXd sos = butterworth_lowpass(order, d.cutoff_hz, d.rate_hz).matrix();
      SCOPED_TRACE("order " + std::to_string(order) + ", fc " + std::to_string(d.cutoff_hz));
      EXPECT_NEAR(std::abs(test::response(sos, 0.0, d.rate_hz)), 1.0, 1e-12);
      EXPECT_NEAR(std::abs(test::response(sos, d.cutoff_hz, d.rate_hz)), 1.0 / std::sqrt(2.0),
                  1e-12);
    }
  }
}

TEST(Butterworth, MagnitudeFollowsThePrewarpedFormula) {
  const std::vector<double> ratios = {0.05, 0.3, 0.7, 0.95, 1.05, 1.5, 2.0, 4.0, 8.0};
  for (int order = 1; order <= 8; ++order) {
    for (const Design& d : kDesigns) {
      const Eigen::MatrixXd sos = butterworth_lowpass(order, d.cutoff_hz, d.rate_hz).matrix();
      for (double ratio : ratios) {
        const double f = ratio * d.cutoff_hz;
        if (f >= 0.5 * d.rate_hz) continue;
        const double expected = test::butterworth_magnitude(order, f, d.cutoff_hz, d.rate_hz);
        EXPECT_NEAR(std::abs(test::response(sos, f, d.rate_hz)), expected, 1e-11 * expected + 1e-15)
            << "order " << order << ", fc " << d.cutoff_hz << ", f " << f;
      }
    }
  }
}

TEST(Butterworth, DycaroCutoffRule) {
  EXPECT_DOUBLE_EQ(dycaro_cutoff(650.0, 1), 260.0);
  EXPECT_DOUBLE_EQ(dycaro_cutoff(1000.0, 4), 100.0);
  // 3.125 Hz, DYCARO's real-data setting, comes from 0.8 * 500 / (2 * 64).
  EXPECT_DOUBLE_EQ(dycaro_cutoff(500.0, 64), 3.125);
}

TEST(Butterworth, SectionsMatchScipy) {
  for (int order = 1; order <= 8; ++order) {
    for (const Design& d : kDesigns) {
      std::string why;
      const auto ref = test::run_scipy(order, d.cutoff_hz, d.rate_hz, nullptr, why);
      ASSERT_TRUE(ref) << why << " (deploy/setup.sh installs python3-scipy)";
      const Eigen::MatrixXd ours = butterworth_lowpass(order, d.cutoff_hz, d.rate_hz).matrix();
      ASSERT_EQ(ours.rows(), ref->sos.rows()) << "order " << order;
      for (Eigen::Index i = 0; i < ours.size(); ++i) {
        EXPECT_NEAR(ours(i), ref->sos(i), 1e-12 * std::abs(ref->sos(i)))
            << "order " << order << ", fc " << d.cutoff_hz << ", coefficient " << i
            << " (column-major in sections x 6)";
      }
    }
  }
}

void expect_rejected(int order, double cutoff, double rate, const std::string& words) {
  SCOPED_TRACE("order " + std::to_string(order) + ", cut-off " + std::to_string(cutoff) +
               ", rate " + std::to_string(rate));
  test::expect_input_error([&] { (void)butterworth_lowpass(order, cutoff, rate); }, words);
}

TEST(Butterworth, RejectsBadDesigns) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(0, 10.0, 100.0, "order 0");
  expect_rejected(9, 10.0, 100.0, "order 9");
  expect_rejected(-2, 10.0, 100.0, "order -2");
  expect_rejected(4, 0.0, 100.0, "Nyquist");
  expect_rejected(4, -1.0, 100.0, "Nyquist");
  expect_rejected(4, 50.0, 100.0, "Nyquist");
  expect_rejected(4, 70.0, 100.0, "Nyquist");
  expect_rejected(4, nan, 100.0, "Nyquist");
  expect_rejected(4, 10.0, 0.0, "sample rate");
  expect_rejected(4, 10.0, nan, "sample rate");
  EXPECT_THROW((void)dycaro_cutoff(100.0, 0), InputError);
  EXPECT_THROW((void)dycaro_cutoff(-100.0, 2), InputError);
}

TEST(Sos, RejectsUnstableOrNonFiniteSections) {
  EXPECT_THROW(Sos({}), InputError);
  EXPECT_THROW(Sos({Biquad{1, 0, 0, -2.0, 1.0}}), InputError);  // double pole at z = 1
  EXPECT_THROW(Sos({Biquad{1, 0, 0, 0.0, 1.5}}), InputError);   // |poles| = sqrt(1.5)
  EXPECT_THROW(Sos({Biquad{std::numeric_limits<double>::infinity(), 0, 0, 0, 0}}), InputError);
  EXPECT_NO_THROW(Sos({Biquad{1, 0, 0, -1.8, 0.81}}));  // double pole at 0.9
}

}  // namespace
}  // namespace dynid::signal
