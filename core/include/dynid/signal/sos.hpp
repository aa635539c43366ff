#pragma once
// A digital IIR filter as a cascade of second-order sections (SOS).
//
// Why sections: a high-order filter with poles close to z = 1 (low cut-off / high sample rate,
// the usual case here: a few Hz at hundreds of Hz) loses all its accuracy as one polynomial;
// as a cascade of biquads each section keeps its own poles accurate.
#include <Eigen/Core>
#include <vector>

namespace dynid::signal {

// One section H(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2), i.e. a0 = 1.
// Run in transposed direct form II: two delays per section.
struct Biquad {
  double b0 = 0, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
};

// A stable cascade of sections, applied first to last.
class Sos {
 public:
  // Throws InputError when there is no section, a coefficient is not finite, or a section is
  // not strictly stable (both poles inside the unit circle): the zero-phase filters need the
  // steady state of every section, which an unstable or marginal section does not have.
  explicit Sos(std::vector<Biquad> sections);

  const std::vector<Biquad>& sections() const { return sections_; }
  Eigen::Index size() const { return static_cast<Eigen::Index>(sections_.size()); }

  // scipy's layout: one row per section, [b0 b1 b2 1 a1 a2].
  Eigen::MatrixXd matrix() const;

 private:
  std::vector<Biquad> sections_;
};

}  // namespace dynid::signal
