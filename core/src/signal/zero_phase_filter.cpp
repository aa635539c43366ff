#include "dynid/signal/zero_phase_filter.hpp"

#include <algorithm>
#include <string>

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

}  // namespace dynid::signal
