#pragma once
// Small independent helpers for the signal tests: the textbook Butterworth magnitude, a
// frequency response evaluated straight from SOS coefficients, and test signals.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <string>

#include "dynid/error.hpp"

namespace dynid::signal::test {

// |H(f)| of a digital Butterworth low-pass designed by the prewarped bilinear transform.
inline double butterworth_magnitude(int order, double f, double fc, double fs) {
  const double ratio = std::tan(std::numbers::pi * f / fs) / std::tan(std::numbers::pi * fc / fs);
  return 1.0 / std::sqrt(1.0 + std::pow(ratio, 2 * order));
}

// H(exp(i 2 pi f / fs)) of the cascade whose rows are [b0 b1 b2 a0 a1 a2].
inline std::complex<double> response(const Eigen::MatrixXd& sos, double f, double fs) {
  const std::complex<double> zinv = std::polar(1.0, -2.0 * std::numbers::pi * f / fs);
  std::complex<double> h = 1.0;
  for (Eigen::Index i = 0; i < sos.rows(); ++i) {
    const auto num = sos(i, 0) + zinv * (sos(i, 1) + zinv * sos(i, 2));
    const auto den = sos(i, 3) + zinv * (sos(i, 4) + zinv * sos(i, 5));
    h *= num / den;
  }
  return h;
}

// Channels of a random walk plus noise, a sine and a step: slow and fast content, non-zero
// ends (so the edge handling matters). Deterministic for a given seed.
inline Eigen::MatrixXd test_signal(Eigen::Index rows, Eigen::Index cols, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  Eigen::MatrixXd x(rows, cols);
  for (Eigen::Index c = 0; c < cols; ++c) {
    double walk = 3.0 * noise(rng);
    for (Eigen::Index k = 0; k < rows; ++k) {
      walk += 0.1 * noise(rng);
      const double sine = 2.0 * std::sin(0.013 * static_cast<double>(k * (c + 1)) + 0.3);
      const double step = k > rows / 3 ? 1.5 : 0.0;
      x(k, c) = walk + sine + step + 0.5 * noise(rng);
    }
  }
  return x;
}

// Expects call() to throw InputError whose message contains `words`.
template <class Call>
void expect_input_error(Call call, const std::string& words) {
  try {
    call();
    ADD_FAILURE() << "accepted; expected an InputError saying \"" << words << "\"";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

}  // namespace dynid::signal::test
