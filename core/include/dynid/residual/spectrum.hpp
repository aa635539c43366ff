#pragma once
// Amplitude spectrum of a sampled signal (FFTW), for residual plots: where in frequency the
// residual lives says much about its cause (a slow road grade near 0 Hz, a tyre or suspension
// mode near its resonance, a lag at the excitation's frequency).
//
// Contract: the mean is removed, a Hann window applied, the one-sided DFT taken and scaled so
// that a sinusoid of amplitude A at a bin frequency reads A (2 / sum of the window).
// frequency_hz[i] = i / (n T), i = 0 .. n/2. InputError for fewer than 4 samples, a
// non-positive or non-finite period, or a non-finite sample.
#include <Eigen/Core>

namespace dynid::residual {

struct Spectrum {
  Eigen::VectorXd frequency_hz;
  Eigen::VectorXd amplitude;
};

Spectrum amplitude_spectrum(const Eigen::VectorXd& x, double sample_period);

}  // namespace dynid::residual
