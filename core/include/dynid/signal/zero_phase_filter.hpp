#pragma once
// Offline zero-phase (forward-backward) filtering, as DYCARO's script_filtre does with Matlab's
// filtfilt: the phase of the forward pass is undone by the backward pass, so filtered signals
// stay aligned in time with each other (a lag would bias every identified parameter), and the
// magnitude response is |H|^2.
//
// Edge handling is exactly scipy.signal.sosfiltfilt with its defaults, so results compare with
// scipy to rounding error:
//  - the signal is extended at each end by padlen samples of odd extension
//    (2 x[0] - x[i] before the start, 2 x[n-1] - x[n-1-i] after the end, i = 1..padlen);
//  - each pass starts with every section in its steady state for a constant input equal to the
//    first sample that pass sees, so a constant signal goes through unchanged.
#include <Eigen/Core>

#include "dynid/signal/sos.hpp"

namespace dynid::signal {

// scipy's default pad length: 3 * (2 * sections + 1 - min(#sections with b2 == 0,
// #sections with a2 == 0)).
Eigen::Index zero_phase_padlen(const Sos& sos);

// Filters each column (a channel) of x, rows = samples (a VectorXd converts to one channel). Throws
// InputError when x has no more than zero_phase_padlen(sos) rows, or when a sample is NaN or
// infinite (naming the channel and the sample index).
Eigen::MatrixXd zero_phase_filter(const Sos& sos, const Eigen::MatrixXd& x);

// How far the edges reach into a filtered signal: the smallest d >= 0 such that, for a sample d
// or more samples inside an end, at most `outside_share` of the zero-phase impulse response's
// l1 mass (|H|^2's response, centred on the sample) falls beyond that end. Closer to an end, more
// of the sample's value comes from the odd extension and the steady-state starts instead of the
// signal, and the error this makes is not noise: it follows the signal's curvature at the end,
// the same in every repetition of a run (what a model row must not carry). outside_share in
// (0, 0.5), and a response that has not decayed within 2^20 samples (a cut-off under about 2e-5
// of the sample rate): InputError. For the 5th-order low-pass at 0.05 of the sample rate and
// outside_share 0.01: 35 samples (1.75 / cut-off).
Eigen::Index zero_phase_edge_reach(const Sos& sos, double outside_share);

}  // namespace dynid::signal
