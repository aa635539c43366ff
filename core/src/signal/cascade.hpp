#pragma once
// Private building blocks of the signal area: running a cascade of sections over samples, its
// steady state and the odd extension at the edges. Both the offline and the streaming
// zero-phase filters use these, so their common parts are the same operations to the bit.
#include <Eigen/Core>

#include "dynid/signal/sos.hpp"

namespace dynid::signal::detail {

// One sample through the cascade; z holds the two delays of each section, in section order.
inline double step(const std::vector<Biquad>& sections, double* z, double x) {
  for (const Biquad& s : sections) {
    const double y = s.b0 * x + z[0];
    z[0] = s.b1 * x - s.a1 * y + z[1];
    z[1] = s.b2 * x - s.a2 * y;
    x = y;
    z += 2;
  }
  return x;
}

// In place, first to last sample.
inline void run_forward(const Sos& sos, double* z, double* data, Eigen::Index n) {
  for (Eigen::Index k = 0; k < n; ++k) data[k] = step(sos.sections(), z, data[k]);
}

// In place, last to first sample.
inline void run_backward(const Sos& sos, double* z, double* data, Eigen::Index n) {
  for (Eigen::Index k = n - 1; k >= 0; --k) data[k] = step(sos.sections(), z, data[k]);
}

// L independent signals at once, interleaved: sample k of lane l at data[k * L + l], and the
// delays of section s in z[2 s L + l] and z[(2 s + 1) L + l]. Each lane gets exactly step()'s
// operations in the same order, so its output is step()'s to the bit; the lanes only give the
// processor independent work (one signal through the cascade is a chain of dependent
// multiply-adds whose latency, not the arithmetic, sets the speed).
template <int L>
inline void step_lanes(const std::vector<Biquad>& sections, double* __restrict z,
                       double* __restrict x) {
  for (const Biquad& s : sections) {
    for (int l = 0; l < L; ++l) {
      const double y = s.b0 * x[l] + z[l];
      z[l] = s.b1 * x[l] - s.a1 * y + z[L + l];
      z[L + l] = s.b2 * x[l] - s.a2 * y;
      x[l] = y;
    }
    z += 2 * L;
  }
}

template <int L>
inline void run_forward_lanes(const Sos& sos, double* z, double* data, Eigen::Index n) {
  for (Eigen::Index k = 0; k < n; ++k) step_lanes<L>(sos.sections(), z, data + k * L);
}

template <int L>
inline void run_backward_lanes(const Sos& sos, double* z, double* data, Eigen::Index n) {
  for (Eigen::Index k = n - 1; k >= 0; --k) step_lanes<L>(sos.sections(), z, data + k * L);
}

// The delays of every section once a unit constant input has gone through forever (scipy's
// sosfilt_zi). Scaling it by a value v puts the cascade in steady state for the input v.
Eigen::VectorXd unit_steady_state(const Sos& sos);

// The odd extension before x[0] (2 x[0] - x[padlen], ..., 2 x[0] - x[1]) and after x[n-1]
// (2 x[n-1] - x[n-2], ..., 2 x[n-1] - x[n-1-padlen]), written into out[0..padlen).
// Need padlen < n.
void odd_pad_start(const double* x, Eigen::Index padlen, double* out);
void odd_pad_end(const double* x, Eigen::Index n, Eigen::Index padlen, double* out);

}  // namespace dynid::signal::detail
