#include "dynid/signal/zero_phase_filter.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cascade.hpp"
#include "checks.hpp"
#include "dynid/error.hpp"

namespace dynid::signal {

Eigen::Index zero_phase_padlen(const Sos& sos) {
  // scipy counts a section with b2 == 0 and a2 == 0 (a first-order section) as one tap less.
  Eigen::Index b2_zero = 0;
  Eigen::Index a2_zero = 0;
  for (const Biquad& s : sos.sections()) {
    b2_zero += s.b2 == 0.0 ? 1 : 0;
    a2_zero += s.a2 == 0.0 ? 1 : 0;
  }
  return 3 * (2 * sos.size() + 1 - std::min(b2_zero, a2_zero));
}

Eigen::MatrixXd zero_phase_filter(const Sos& sos, const Eigen::MatrixXd& x) {
  const Eigen::Index padlen = zero_phase_padlen(sos);
  const Eigen::Index n = x.rows();
  if (n <= padlen)
    throw InputError("zero_phase_filter: the signal has " + std::to_string(n) +
                     " samples; the edge padding needs more than " + std::to_string(padlen));
  detail::require_finite(x, 0, "zero_phase_filter");

  const Eigen::VectorXd unit = detail::unit_steady_state(sos);
  Eigen::MatrixXd y(n, x.cols());
  Eigen::VectorXd ext(n + 2 * padlen);
  Eigen::VectorXd z(unit.size());
  for (Eigen::Index c = 0; c < x.cols(); ++c) {
    const Eigen::VectorXd column = x.col(c);
    detail::odd_pad_start(column.data(), padlen, ext.data());
    ext.segment(padlen, n) = column;
    detail::odd_pad_end(column.data(), n, padlen, ext.data() + padlen + n);
    z = unit * ext(0);
    detail::run_forward(sos, z.data(), ext.data(), ext.size());
    z = unit * ext(ext.size() - 1);
    detail::run_backward(sos, z.data(), ext.data(), ext.size());
    y.col(c) = ext.segment(padlen, n);
  }
  return y;
}

namespace {

// The longest half-length tried: 2^20 samples (16 MB of work buffer). A response that has not
// decayed by then is an announcement's cut-off far below any test's (under 0.002 % of the sample
// rate), refused rather than searched at any cost.
constexpr Eigen::Index kLongestHalf = Eigen::Index{1} << 20;

// |g[j]| for j = 0, 1, ... of the zero-phase impulse response g (symmetric: g[-j] = g[j]), long
// enough that what is cut off is below 1e-15 of the l1 mass: the forward pass of an impulse in
// the middle of 2 n + 1 zeros, then the backward pass, from rest, doubling n until the tail at
// both ends is negligible (the stable poles make it decay geometrically). InputError when it has
// not decayed within kLongestHalf.
std::vector<double> zero_phase_impulse_magnitudes(const Sos& sos) {
  for (Eigen::Index half = 64; half <= kLongestHalf; half *= 2) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * half + 1);
    x(half) = 1.0;
    Eigen::VectorXd z = Eigen::VectorXd::Zero(2 * sos.size());
    detail::run_forward(sos, z.data(), x.data(), x.size());
    z.setZero();
    detail::run_backward(sos, z.data(), x.data(), x.size());
    const double mass = x.cwiseAbs().sum();
    const Eigen::Index edge = half / 8;
    const double cut = x.head(edge).cwiseAbs().sum() + x.tail(edge).cwiseAbs().sum();
    if (cut <= 1e-15 * mass) {
      std::vector<double> out(static_cast<std::size_t>(half + 1));
      for (Eigen::Index j = 0; j <= half; ++j) out[static_cast<std::size_t>(j)] = std::abs(x(half + j));
      return out;
    }
  }
  throw InputError("zero_phase_edge_reach: the filter's impulse response has not decayed within " +
                   std::to_string(kLongestHalf) + " samples; raise the cut-off or lower the sample rate");
}

}  // namespace

Eigen::Index zero_phase_edge_reach(const Sos& sos, double outside_share) {
  if (!(outside_share > 0.0 && outside_share < 0.5))
    throw InputError("zero_phase_edge_reach: outside share " + std::to_string(outside_share) +
                     " is outside (0, 0.5)");
  const std::vector<double> g = zero_phase_impulse_magnitudes(sos);
  double mass = g[0];
  for (std::size_t j = 1; j < g.size(); ++j) mass += 2.0 * g[j];
  // beyond = the mass of g[j] for j > d, on one side: what lies past an end d samples away.
  double beyond = 0.5 * (mass - g[0]);
  Eigen::Index d = 0;
  for (; static_cast<std::size_t>(d + 1) < g.size() && beyond > outside_share * mass; ++d)
    beyond -= g[static_cast<std::size_t>(d + 1)];
  return d;
}

}  // namespace dynid::signal
