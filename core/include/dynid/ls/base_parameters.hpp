#pragma once
// Base parameters: which standard parameters the data can identify, and how the others regroup
// (Venture 2003, Annex 1; seeds/venture-2003.en.md §4.6).
//
// A column j of W is *eliminated* when it is negligible (not excited): its norm is below
// `zero_tolerance` times the largest column norm (DYCARO's "tolerance 0"). Among the remaining
// columns, taken in their natural order (so that, as in DYCARO, earlier parameters are kept and
// later ones regrouped into them), a column is *dependent* when its component orthogonal to the
// columns already kept is below tau = r * epsilon * max_i |R_ii| (DYCARO's QR tolerance, r the
// row count). Dependent columns satisfy W_dep = W_base * beta, so the base parameters are
//     X_base = X_s,base + beta * X_s,dep                      (E5-15, beta = R1^-1 R2)
// and a kept column whose row of beta is non-zero is *regrouped* (its value is a combination).
//
// Improvement over the source: the test is made on columns scaled to unit norm. DYCARO's
// max|R_ii| depends on the units of each parameter (grams vs kilograms change which columns
// look dependent); on equilibrated columns tau is the relative loss of rank that rounding can
// cause, whatever the units, and ill-conditioned but full-rank problems (NIST Filip) are kept.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace dynid::ls {

enum class ParameterStatus {
  kIdentified,  ///< independent column with nothing regrouped into it
  kRegrouped,   ///< independent column whose value absorbs dependent ones (see relation)
  kDependent,   ///< linear combination of earlier columns: regrouped into them, no own value
  kEliminated,  ///< negligible column (not excited): no value
  // What the data say about an identified column's value (never set by
  // analyse_base_parameters; model::classify_parameters refines kIdentified into these,
  // dynid/model/parameter_status.hpp, where the rules are stated):
  kPoorlyIdentified,  ///< relative std above DYCARO's limits
  kNotExcited,        ///< the run carries (almost) no information about it
  kImplausible,       ///< outside the model's physical bounds by more than 2 std
};

const char* to_string(ParameterStatus status);

struct BaseParameterOptions {
  /// DYCARO's QR tolerance epsilon: the data perturbation level (2^-52: rounding only).
  double epsilon = 0x1p-52;
  /// DYCARO's "tolerance 0": relative column norm under which a column is eliminated. The
  /// effective threshold is never below tau, so exactly zero columns are always eliminated.
  double zero_tolerance = 0.0;
};

struct BaseParameterAnalysis {
  std::vector<Eigen::Index> base;        ///< kept columns, increasing
  std::vector<Eigen::Index> dependent;   ///< regrouped columns, increasing
  std::vector<Eigen::Index> eliminated;  ///< negligible columns, increasing
  /// beta (base.size() x dependent.size()): W(:, dependent) = W(:, base) * beta.
  Eigen::MatrixXd regrouping;
  std::vector<ParameterStatus> status;  ///< per standard parameter
  double tolerance = 0.0;               ///< tau actually used (on unit-norm columns)

  Eigen::Index rank() const { return static_cast<Eigen::Index>(base.size()); }
  /// The base-parameter values from standard ones: X_s(base) + beta X_s(dependent).
  Eigen::VectorXd base_values(const Eigen::Ref<const Eigen::VectorXd>& standard) const;
  /// A readable relation for base parameter k, e.g. "M + 0.5*MX - 2*MZ".
  std::string relation(Eigen::Index k, const std::vector<std::string>& names) const;
};

/// Analyses the column structure of W from its triangular factor R (n x n, R^T R = W^T W),
/// e.g. Accumulator::augmented_r().topLeftCorner(n, n). `row_count` is r in tau.
BaseParameterAnalysis analyse_base_parameters(const Eigen::Ref<const Eigen::MatrixXd>& R,
                                              double row_count,
                                              const BaseParameterOptions& options = {});

}  // namespace dynid::ls
