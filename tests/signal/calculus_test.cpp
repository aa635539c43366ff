// Central differences, trapezoidal integration and decimation, offline and over chunks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "dynid/error.hpp"
#include "dynid/signal/decimate.hpp"
#include "dynid/signal/derivative.hpp"
#include "dynid/signal/integrate.hpp"
#include "test_support.hpp"

namespace dynid::signal {
namespace {

Eigen::VectorXd times(Eigen::Index n, double period, double start) {
  Eigen::VectorXd t(n);
  for (Eigen::Index k = 0; k < n; ++k) t(k) = start + period * static_cast<double>(k);
  return t;
}

// Inside, the five-point stencil's gain on sin(w t) is (8 sin(wT) - sin(2 wT)) / (6 wT); next to
// the ends, the three-point one's sin(wT) / (wT).
TEST(Derivative, CentralDifferenceOfSineHasTheStencilsGain) {
  const double period = 0.01;
  const double w = 2.0 * std::numbers::pi * 1.3;
  const Eigen::VectorXd t = times(500, period, 0.2);
  const Eigen::VectorXd x = (w * t.array()).sin();
  const Eigen::VectorXd dx = derivative(x, period);
  const double wt = w * period;
  const double five_point = (8.0 * std::sin(wt) - std::sin(2.0 * wt)) / (6.0 * period);
  for (Eigen::Index k = 2; k + 2 < t.size(); ++k)
    EXPECT_NEAR(dx(k), five_point * std::cos(w * t(k)), 1e-12 * w) << k;
  for (Eigen::Index k : {Eigen::Index{1}, t.size() - 2})
    EXPECT_NEAR(dx(k), std::sin(wt) / period * std::cos(w * t(k)), 1e-12 * w) << k;
  // At 5 Hz and 100 Hz (the default cut-off) the five-point gain is within 4e-4 of 1, the
  // three-point one 1.6 % below it.
  const double at_cutoff = 2.0 * std::numbers::pi * 5.0 * period;
  EXPECT_NEAR((8.0 * std::sin(at_cutoff) - std::sin(2.0 * at_cutoff)) / (6.0 * at_cutoff), 1.0, 4e-4);
  EXPECT_NEAR(std::sin(at_cutoff) / at_cutoff, 0.984, 1e-3);
}

TEST(Derivative, ExactOnQuarticsInside) {
  const double period = 0.02;
  const Eigen::VectorXd t = times(60, period, -0.5);
  const Eigen::VectorXd x = 1.0 + t.array() - 2.0 * t.array().pow(3) + 0.5 * t.array().pow(4);
  const Eigen::VectorXd dx = derivative(x, period);
  for (Eigen::Index k = 2; k + 2 < t.size(); ++k)
    EXPECT_NEAR(dx(k), 1.0 - 6.0 * t(k) * t(k) + 2.0 * std::pow(t(k), 3), 1e-11) << k;
}

TEST(Derivative, ExactOnQuadraticsEndsIncluded) {
  const double period = 0.05;
  const Eigen::VectorXd t = times(40, period, -1.0);
  Eigen::MatrixXd x(t.size(), 2);
  x.col(0) = 3.0 - 2.0 * t.array() + 0.75 * t.array().square();
  x.col(1) = -1.0 + 4.0 * t.array().square();
  const Eigen::MatrixXd dx = derivative(x, period);
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    EXPECT_NEAR(dx(k, 0), -2.0 + 1.5 * t(k), 1e-12) << k;
    EXPECT_NEAR(dx(k, 1), 8.0 * t(k), 1e-12) << k;
  }
}

TEST(Derivative, StreamingHasTwoSamplesLookAheadAndEqualsOffline) {
  const Eigen::MatrixXd x = test::test_signal(300, 2, 21u);
  const Eigen::MatrixXd offline = derivative(x, 0.002);
  for (Eigen::Index size : {1, 2, 7, 300}) {
    StreamingDerivative d(2, 0.002);
    Eigen::MatrixXd y(x.rows(), 2);
    Eigen::Index out = 0;
    for (Eigen::Index in = 0; in < x.rows(); in += size) {
      const Eigen::Index m = std::min(size, x.rows() - in);
      const Eigen::MatrixXd got = d.push(x.middleRows(in, m));
      y.middleRows(out, got.rows()) = got;
      out += got.rows();
      // x'[0] and x'[1] out once x[2] is in, x'[k >= 2] once x[k+2] is
      EXPECT_EQ(out, in + m >= 3 ? std::max<Eigen::Index>(2, in + m - 2) : 0);
    }
    y.bottomRows(2) = d.finish();
    EXPECT_EQ(y, offline) << "chunk size " << size;
  }
}

TEST(Derivative, StreamingStateRestoresExactlyAndIsChecked) {
  const Eigen::MatrixXd x = test::test_signal(50, 2, 22u);
  const Eigen::MatrixXd offline = derivative(x, 0.01);
  for (Eigen::Index cut : {0, 1, 2, 3, 4, 5, 20}) {
    StreamingDerivative first(2, 0.01);
    Eigen::MatrixXd y(x.rows(), 2);
    const Eigen::MatrixXd a = first.push(x.topRows(cut));
    StreamingDerivative second(2, 0.01);
    second.restore(first.state());
    const Eigen::MatrixXd b = second.push(x.bottomRows(x.rows() - cut));
    y << a, b, second.finish();
    EXPECT_EQ(y, offline) << "cut at " << cut;
  }
  StreamingDerivative d(2, 0.01);
  (void)d.push(x.topRows(10));
  StreamingDerivative::State bad = d.state();
  bad.samples_out = 3;
  EXPECT_THROW(d.restore(bad), InputError);
  EXPECT_THROW(StreamingDerivative(3, 0.01).restore(d.state()), InputError);
  EXPECT_EQ(d.samples_out(), 8);
}

TEST(Derivative, RejectsShortOrNonFiniteInput) {
  EXPECT_THROW((void)derivative(Eigen::VectorXd::Ones(2), 0.01), InputError);
  EXPECT_THROW((void)derivative(Eigen::VectorXd::Ones(5), 0.0), InputError);
  EXPECT_THROW((void)derivative(Eigen::VectorXd::Ones(5), -0.01), InputError);
  StreamingDerivative d(1, 0.01);
  (void)d.push(Eigen::VectorXd::Ones(2));
  EXPECT_THROW((void)d.finish(), InputError);  // 2 samples are too few
  Eigen::VectorXd bad = Eigen::VectorXd::Ones(4);
  bad(3) = std::numeric_limits<double>::quiet_NaN();
  test::expect_input_error([&] { (void)d.push(bad); }, "channel 0, sample 5 is NaN");
  EXPECT_EQ(d.samples_in(), 2);
  EXPECT_EQ(d.push(Eigen::VectorXd::Constant(1, 4.0)).rows(), 2);
  EXPECT_EQ(d.finish().rows(), 1);  // 3 samples: x'[0], x'[1] out, x'[2] one-sided
  StreamingDerivative four(1, 0.01);
  EXPECT_EQ(four.push(Eigen::VectorXd::Ones(4)).rows(), 2);
  EXPECT_EQ(four.finish().rows(), 2);  // x'[2] three-point, x'[3] one-sided
}

TEST(Trapezoid, ExactOnLinearFunctions) {
  const double period = 0.01;
  const Eigen::VectorXd t = times(1000, period, 0.0);
  const Eigen::VectorXd x = 2.5 - 3.0 * t.array();
  const Eigen::VectorXd integral = cumulative_trapezoid(x, period);
  for (Eigen::Index k = 0; k < t.size(); ++k)
    EXPECT_NEAR(integral(k), 2.5 * t(k) - 1.5 * t(k) * t(k), 1e-12 * (1.0 + std::abs(integral(k))))
        << k;
}

TEST(Trapezoid, StreamingEqualsOfflineAndRejectsNonFinite) {
  const Eigen::MatrixXd x = test::test_signal(200, 3, 5u);
  const Eigen::MatrixXd offline = cumulative_trapezoid(x, 0.1);
  StreamingTrapezoid integrator(3, 0.1);
  Eigen::MatrixXd y(x.rows(), 3);
  for (Eigen::Index in = 0; in < x.rows(); in += 13) {
    const Eigen::Index m = std::min<Eigen::Index>(13, x.rows() - in);
    if (in == 26) {
      Eigen::MatrixXd bad = x.middleRows(in, m);
      bad(0, 2) = std::numeric_limits<double>::infinity();
      EXPECT_THROW((void)integrator.push(bad), InputError);
    }
    y.middleRows(in, m) = integrator.push(x.middleRows(in, m));
  }
  EXPECT_EQ(y, offline);
  EXPECT_THROW((void)cumulative_trapezoid(x, std::numeric_limits<double>::quiet_NaN()), InputError);
}

TEST(Decimate, KeepsEveryRthSampleFromTheFirst) {
  Eigen::MatrixXd x(10, 2);
  for (Eigen::Index k = 0; k < 10; ++k) x.row(k) << static_cast<double>(k), -static_cast<double>(k);
  const Eigen::MatrixXd y = decimate(x, 3);
  ASSERT_EQ(y.rows(), 4);
  for (Eigen::Index i = 0; i < 4; ++i) {
    EXPECT_EQ(y(i, 0), 3.0 * static_cast<double>(i));
    EXPECT_EQ(y(i, 1), -3.0 * static_cast<double>(i));
  }
  EXPECT_EQ(decimate(x, 1), x);
  EXPECT_EQ(decimate(x, 20).rows(), 1);
  EXPECT_THROW((void)decimate(x, 0), InputError);
}

TEST(Decimate, StreamingKeepsTheSameSamples) {
  Eigen::VectorXd x(1000);
  for (Eigen::Index k = 0; k < x.size(); ++k) x(k) = static_cast<double>(k);
  std::mt19937 rng(2u);
  std::uniform_int_distribution<Eigen::Index> size(1, 17);
  StreamingDecimator decimator(7);
  std::vector<double> kept;
  for (Eigen::Index in = 0; in < x.size();) {
    const Eigen::Index m = std::min(size(rng), x.size() - in);
    const Eigen::MatrixXd got = decimator.push(x.segment(in, m));
    for (Eigen::Index i = 0; i < got.rows(); ++i) kept.push_back(got(i, 0));
    in += m;
  }
  ASSERT_EQ(kept.size(), 143u);  // 0, 7, ..., 994
  for (std::size_t i = 0; i < kept.size(); ++i) EXPECT_EQ(kept[i], 7.0 * static_cast<double>(i));
}

}  // namespace
}  // namespace dynid::signal
