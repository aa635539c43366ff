#pragma once
// Digital low-pass Butterworth design (bilinear transform with frequency prewarping).
#include "dynid/signal/sos.hpp"

namespace dynid::signal {

// Low-pass Butterworth of the given order (1 to 8), -3 dB at cutoff_hz, for samples taken at
// sample_rate_hz (both in Hz). Magnitude response, exactly (prewarping puts the cut-off where
// it is asked):
//   |H(f)| = 1 / sqrt(1 + (tan(pi f / fs) / tan(pi fc / fs))^(2 order)),  H(0) = 1.
// Sections are ordered and paired like scipy's butter(order, fc, fs=fs, output='sos')
// (zpk2sos, pairing 'nearest': the pole closest to the unit circle in the last section, the
// overall gain in the first section), so coefficients compare one to one with scipy.
// Throws InputError when the order is outside 1..8, the sample rate is not a positive finite
// number, or the cut-off is not strictly between 0 and the Nyquist frequency sample_rate_hz / 2.
Sos butterworth_lowpass(int order, double cutoff_hz, double sample_rate_hz);

// DYCARO's `script_filtre` cut-off rule (venture-2003 §4.3, E5-16): f_c = 0.8 f_e / (2 odmf),
// a sub-multiple of the Nyquist frequency; it is also Matlab's decimate() anti-aliasing
// cut-off for a decimation by odmf. Throws InputError unless sample_rate_hz is positive and
// finite and odmf >= 1.
double dycaro_cutoff(double sample_rate_hz, int odmf);

}  // namespace dynid::signal
