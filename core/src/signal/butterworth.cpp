#include "dynid/signal/butterworth.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include "dynid/error.hpp"

namespace dynid::signal {
namespace {

using Complex = std::complex<double>;

void check_design(int order, double cutoff_hz, double sample_rate_hz) {
  if (order < 1 || order > 8)
    throw InputError("butterworth_lowpass: order " + std::to_string(order) + " is outside 1..8");
  if (!std::isfinite(sample_rate_hz) || sample_rate_hz <= 0.0)
    throw InputError("butterworth_lowpass: sample rate " + std::to_string(sample_rate_hz) +
                     " Hz must be positive and finite");
  if (!std::isfinite(cutoff_hz) || cutoff_hz <= 0.0 || cutoff_hz >= 0.5 * sample_rate_hz)
    throw InputError("butterworth_lowpass: cut-off " + std::to_string(cutoff_hz) +
                     " Hz must be strictly between 0 and the Nyquist frequency " +
                     std::to_string(0.5 * sample_rate_hz) + " Hz");
}

// Index of the pole closest to the unit circle, among those accepted by `keep`.
template <class Keep>
std::size_t worst_pole(const std::vector<Complex>& poles, Keep keep) {
  std::size_t best = poles.size();
  for (std::size_t i = 0; i < poles.size(); ++i) {
    if (!keep(poles[i])) continue;
    if (best == poles.size() ||
        std::abs(1.0 - std::abs(poles[i])) < std::abs(1.0 - std::abs(poles[best])))
      best = i;
  }
  return best;
}

// Removes and returns the zero nearest to p.
double take_nearest_zero(std::vector<double>& zeros, Complex p) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < zeros.size(); ++i)
    if (std::abs(zeros[i] - p) < std::abs(zeros[best] - p)) best = i;
  const double z = zeros[best];
  zeros.erase(zeros.begin() + static_cast<std::ptrdiff_t>(best));
  return z;
}

template <class T>
T take(std::vector<T>& v, std::size_t i) {
  const T x = v[i];
  v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
  return x;
}

// Pairs poles and zeros into sections as scipy's zpk2sos(pairing='nearest') does: the pole
// closest to the unit circle (the most resonant, most sensitive) goes into the last section,
// with the zeros nearest to it. `poles` holds one pole per conjugate pair plus the real ones
// (an even count of real ones, so a real pole always pairs with another real pole).
std::vector<Biquad> pair_sections(std::vector<Complex> poles, std::vector<double> zeros) {
  const auto real =
      std::count_if(poles.begin(), poles.end(), [](Complex p) { return p.imag() == 0.0; });
  std::vector<Biquad> sections(poles.size() - static_cast<std::size_t>(real) / 2);
  for (auto section = sections.rbegin(); section != sections.rend(); ++section) {
    const Complex p1 = take(poles, worst_pole(poles, [](Complex) { return true; }));
    const Complex p2 =
        p1.imag() == 0.0 ? take(poles, worst_pole(poles, [](Complex p) { return p.imag() == 0.0; }))
                         : std::conj(p1);
    const double z1 = take_nearest_zero(zeros, p1);
    const double z2 = take_nearest_zero(zeros, p1);
    *section = Biquad{1.0, -(z1 + z2), z1 * z2, -(p1 + p2).real(), (p1 * p2).real()};
  }
  return sections;
}

}  // namespace

Sos butterworth_lowpass(int order, double cutoff_hz, double sample_rate_hz) {
  check_design(order, cutoff_hz, sample_rate_hz);
  // Prewarping: the bilinear transform maps the analog frequency tan(pi f / fs) (in units of
  // the transform's 2 fs) to f, so scaling the analog prototype by t puts -3 dB exactly at fc.
  const double t = std::tan(std::numbers::pi * cutoff_hz / sample_rate_hz);
  std::vector<Complex> poles;  // digital, one per conjugate pair
  std::vector<double> zeros(static_cast<std::size_t>(order), -1.0);  // all at z = -1 (f = fs/2)
  Complex gain_denominator = 1.0;
  for (int m = order - 1; m >= 0; m -= 2) {
    // Analog prototype pole s = -exp(i pi m / (2 order)), on the unit circle, left half plane.
    const Complex s = -std::exp(Complex(0.0, std::numbers::pi * m / (2.0 * order)));
    poles.push_back((1.0 + t * s) / (1.0 - t * s));
    gain_denominator *= (m == 0) ? (1.0 - t * s) : (1.0 - t * s) * (1.0 - t * std::conj(s));
  }
  if (order % 2 == 1) {
    // Odd order: a first-order section written as a biquad with a pole and a zero at z = 0.
    poles.emplace_back(0.0);
    zeros.push_back(0.0);
  }
  std::vector<Biquad> sections = pair_sections(std::move(poles), std::move(zeros));
  // Analog gain t^order, through the bilinear transform: unit gain at DC.
  const double gain = std::pow(t, order) / gain_denominator.real();
  sections.front().b0 *= gain;
  sections.front().b1 *= gain;
  sections.front().b2 *= gain;
  return Sos(std::move(sections));
}

double dycaro_cutoff(double sample_rate_hz, int odmf) {
  if (!std::isfinite(sample_rate_hz) || sample_rate_hz <= 0.0)
    throw InputError("dycaro_cutoff: sample rate " + std::to_string(sample_rate_hz) +
                     " Hz must be positive and finite");
  if (odmf < 1) throw InputError("dycaro_cutoff: odmf " + std::to_string(odmf) + " must be >= 1");
  return 0.8 * sample_rate_hz / (2.0 * odmf);
}

}  // namespace dynid::signal
