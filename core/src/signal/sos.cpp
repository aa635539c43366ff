#include "dynid/signal/sos.hpp"

#include <cmath>
#include <string>

#include "cascade.hpp"
#include "dynid/error.hpp"

namespace dynid::signal {
namespace {

bool finite(const Biquad& s) {
  return std::isfinite(s.b0) && std::isfinite(s.b1) && std::isfinite(s.b2) && std::isfinite(s.a1) &&
         std::isfinite(s.a2);
}

// Both roots of z^2 + a1 z + a2 strictly inside the unit circle (the stability triangle).
bool stable(const Biquad& s) {
  return std::abs(s.a2) < 1.0 && std::abs(s.a1) < 1.0 + s.a2;
}

}  // namespace

Sos::Sos(std::vector<Biquad> sections) : sections_(std::move(sections)) {
  if (sections_.empty()) throw InputError("Sos: a filter needs at least one section");
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    if (!finite(sections_[i]))
      throw InputError("Sos: section " + std::to_string(i) +
                       " has a coefficient that is not finite");
    if (!stable(sections_[i]))
      throw InputError("Sos: section " + std::to_string(i) +
                       " is not strictly stable (a pole on or outside the unit circle)");
  }
}

Eigen::MatrixXd Sos::matrix() const {
  Eigen::MatrixXd m(size(), 6);
  for (Eigen::Index i = 0; i < size(); ++i) {
    const Biquad& s = sections_[static_cast<std::size_t>(i)];
    m.row(i) << s.b0, s.b1, s.b2, 1.0, s.a1, s.a2;
  }
  return m;
}

namespace detail {

Eigen::VectorXd unit_steady_state(const Sos& sos) {
  Eigen::VectorXd z(2 * sos.size());
  double level = 1.0;  // steady input of the current section: the DC gain of those before it
  Eigen::Index i = 0;
  for (const Biquad& s : sos.sections()) {
    // Transposed direct form II at rest with constant input u and output g u:
    //   z1 = (g - b0) u,  z2 = (b2 - a2 g) u,  g = (b0 + b1 + b2) / (1 + a1 + a2).
    // Written as scipy's lfilter_zi solves it, so that rounding matches it closely.
    const double z1 = (s.b1 - s.a1 * s.b0 + (s.b2 - s.a2 * s.b0)) / (1.0 + s.a1 + s.a2);
    z(i) = level * z1;
    z(i + 1) = level * (s.b2 - s.a2 * s.b0 - s.a2 * z1);
    level *= (s.b0 + s.b1 + s.b2) / (1.0 + s.a1 + s.a2);
    i += 2;
  }
  return z;
}

void odd_pad_start(const double* x, Eigen::Index padlen, double* out) {
  for (Eigen::Index i = 0; i < padlen; ++i) out[i] = 2.0 * x[0] - x[padlen - i];
}

void odd_pad_end(const double* x, Eigen::Index n, Eigen::Index padlen, double* out) {
  for (Eigen::Index i = 0; i < padlen; ++i) out[i] = 2.0 * x[n - 1] - x[n - 2 - i];
}

}  // namespace detail
}  // namespace dynid::signal
