#include "dynid/residual/spectrum.hpp"

#include <cmath>
#include <complex>
#include <memory>
#include <mutex>
#include <numbers>
#include <string>
#include <vector>

#include <fftw3.h>

#include "dynid/error.hpp"

namespace dynid::residual {

Spectrum amplitude_spectrum(const Eigen::VectorXd& x, double sample_period) {
  const Eigen::Index n = x.size();
  if (n < 4) throw InputError("spectrum: " + std::to_string(n) + " samples, at least 4 needed");
  if (!(sample_period > 0.0) || !std::isfinite(sample_period))
    throw InputError("spectrum: sample period " + std::to_string(sample_period) + " s is not positive");
  if (!x.allFinite()) throw InputError("spectrum: the signal has a NaN or infinite sample");
  std::vector<double> in(static_cast<std::size_t>(n));
  double window_sum = 0.0;
  const double mean = x.mean();
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                          static_cast<double>(n - 1));
    window_sum += w;
    in[static_cast<std::size_t>(i)] = w * (x(i) - mean);
  }
  const Eigen::Index bins = n / 2 + 1;
  std::vector<std::complex<double>> out(static_cast<std::size_t>(bins));
  {
    // FFTW's planner is not thread-safe (only fftw_execute is): the server's workers may
    // analyse runs at the same time. FFTW_ESTIMATE: no timing measurement while planning.
    static std::mutex planner;
    const std::lock_guard<std::mutex> lock(planner);
    fftw_plan plan = fftw_plan_dft_r2c_1d(static_cast<int>(n), in.data(),
                                          reinterpret_cast<fftw_complex*>(out.data()), FFTW_ESTIMATE);
    fftw_execute(plan);
    fftw_destroy_plan(plan);
  }
  Spectrum s{Eigen::VectorXd(bins), Eigen::VectorXd(bins)};
  for (Eigen::Index i = 0; i < bins; ++i) {
    s.frequency_hz(i) = static_cast<double>(i) / (static_cast<double>(n) * sample_period);
    s.amplitude(i) = 2.0 * std::abs(out[static_cast<std::size_t>(i)]) / window_sum;
  }
  return s;
}

}  // namespace dynid::residual
