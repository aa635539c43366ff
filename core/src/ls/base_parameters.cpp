#include "dynid/ls/base_parameters.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "dynid/error.hpp"

namespace dynid::ls {
namespace {

// Regrouping coefficients below this share of a dependent column are rounding noise: they are
// cleaned to exactly zero, as the source advises (a coefficient of 1e-17 is not a regrouping).
constexpr double kNegligibleShare = 1e-9;

// Greedy natural-order selection of independent columns among `candidates` of `unit` (columns
// scaled to unit norm): a column is kept when its part orthogonal to the kept ones exceeds tau.
// Classical Gram-Schmidt with one re-orthogonalization (CGS2) is accurate to rounding here.
void select_base_columns(const Eigen::MatrixXd& unit, const std::vector<Eigen::Index>& candidates,
                         double tau, BaseParameterAnalysis& out) {
  Eigen::MatrixXd basis(unit.rows(), unit.cols());
  Eigen::Index kept = 0;
  for (Eigen::Index j : candidates) {
    Eigen::VectorXd v = unit.col(j);
    for (int pass = 0; pass < 2; ++pass)
      v -= basis.leftCols(kept) * (basis.leftCols(kept).transpose() * v);
    const double orthogonal = v.norm();
    if (orthogonal > tau) {
      basis.col(kept++) = v / orthogonal;
      out.base.push_back(j);
    } else {
      out.dependent.push_back(j);
    }
  }
}

Eigen::MatrixXd columns(const Eigen::Ref<const Eigen::MatrixXd>& m,
                        const std::vector<Eigen::Index>& which) {
  Eigen::MatrixXd out(m.rows(), static_cast<Eigen::Index>(which.size()));
  for (std::size_t k = 0; k < which.size(); ++k)
    out.col(static_cast<Eigen::Index>(k)) = m.col(which[k]);
  return out;
}

// beta with W_dep = W_base beta, from the triangular factor (R^T R = W^T W, same geometry).
Eigen::MatrixXd regrouping_matrix(const Eigen::Ref<const Eigen::MatrixXd>& R,
                                  const Eigen::VectorXd& norms, const BaseParameterAnalysis& a) {
  if (a.dependent.empty() || a.base.empty())
    return Eigen::MatrixXd::Zero(a.rank(), static_cast<Eigen::Index>(a.dependent.size()));
  const Eigen::MatrixXd base = columns(R, a.base);
  Eigen::MatrixXd beta = base.householderQr().solve(columns(R, a.dependent));
  for (Eigen::Index i = 0; i < beta.rows(); ++i)
    for (Eigen::Index j = 0; j < beta.cols(); ++j) {
      const double share = std::abs(beta(i, j)) * norms(a.base[static_cast<std::size_t>(i)]) /
                           norms(a.dependent[static_cast<std::size_t>(j)]);
      if (share < kNegligibleShare) beta(i, j) = 0.0;
    }
  return beta;
}

std::string format_coefficient(double c) {
  std::ostringstream s;
  s.precision(6);
  s << std::abs(c);
  return s.str();
}

}  // namespace

const char* to_string(ParameterStatus status) {
  switch (status) {
    case ParameterStatus::kIdentified:
      return "identified";
    case ParameterStatus::kRegrouped:
      return "regrouped";
    case ParameterStatus::kDependent:
      return "dependent";
    case ParameterStatus::kEliminated:
      return "eliminated";
    case ParameterStatus::kPoorlyIdentified:
      return "poorly identified";
    case ParameterStatus::kNotExcited:
      return "not excited";
    case ParameterStatus::kImplausible:
      return "implausible";
  }
  return "?";
}

Eigen::VectorXd BaseParameterAnalysis::base_values(
    const Eigen::Ref<const Eigen::VectorXd>& standard) const {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(rank());
  Eigen::VectorXd dep(static_cast<Eigen::Index>(dependent.size()));
  for (std::size_t k = 0; k < base.size(); ++k) x(static_cast<Eigen::Index>(k)) = standard(base[k]);
  for (std::size_t k = 0; k < dependent.size(); ++k)
    dep(static_cast<Eigen::Index>(k)) = standard(dependent[k]);
  if (dep.size() > 0) x += regrouping * dep;
  return x;
}

std::string BaseParameterAnalysis::relation(Eigen::Index k,
                                            const std::vector<std::string>& names) const {
  const auto name_of = [&](Eigen::Index column) {
    const auto c = static_cast<std::size_t>(column);
    return c < names.size() ? names[c] : "X" + std::to_string(column);
  };
  std::string text = name_of(base.at(static_cast<std::size_t>(k)));
  for (std::size_t j = 0; j < dependent.size(); ++j) {
    const double c = regrouping(k, static_cast<Eigen::Index>(j));
    if (c == 0.0) continue;
    text += (c < 0 ? " - " : " + ");
    const std::string magnitude = format_coefficient(c);  // 6 digits: 1.0000000000000002 is 1
    if (magnitude != "1") text += magnitude + "*";
    text += name_of(dependent[j]);
  }
  return text;
}

BaseParameterAnalysis analyse_base_parameters(const Eigen::Ref<const Eigen::MatrixXd>& R,
                                              double row_count,
                                              const BaseParameterOptions& options) {
  if (R.rows() != R.cols() || R.rows() < 1)
    throw InputError("base parameters: R must be square and non-empty, got " +
                     std::to_string(R.rows()) + "x" + std::to_string(R.cols()));
  if (!(options.epsilon > 0.0) || !(options.zero_tolerance >= 0.0))
    throw InputError("base parameters: epsilon must be > 0 and zero_tolerance >= 0");
  const Eigen::Index n = R.cols();
  BaseParameterAnalysis out;
  out.tolerance = std::max(row_count, 1.0) * options.epsilon;

  const Eigen::VectorXd norms = R.colwise().norm().transpose();
  const double largest = norms.maxCoeff();
  const double zero_threshold = std::max(options.zero_tolerance, out.tolerance) * largest;
  std::vector<Eigen::Index> candidates;
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (largest == 0.0 || norms(j) <= zero_threshold) {
      out.eliminated.push_back(j);
    } else {
      candidates.push_back(j);
      unit.col(j) = R.col(j) / norms(j);
    }
  }
  select_base_columns(unit, candidates, out.tolerance, out);
  out.regrouping = regrouping_matrix(R, norms, out);

  out.status.assign(static_cast<std::size_t>(n), ParameterStatus::kIdentified);
  for (Eigen::Index j : out.eliminated)
    out.status[static_cast<std::size_t>(j)] = ParameterStatus::kEliminated;
  for (Eigen::Index j : out.dependent)
    out.status[static_cast<std::size_t>(j)] = ParameterStatus::kDependent;
  // With no dependent column the regrouping matrix has no column and no storage: taking a row
  // of it is pointer arithmetic on null (UBSan, found by tests/fuzz/fuzz_chunk).
  for (std::size_t k = 0; k < out.base.size() && !out.dependent.empty(); ++k)
    if ((out.regrouping.row(static_cast<Eigen::Index>(k)).array() != 0.0).any())
      out.status[static_cast<std::size_t>(out.base[k])] = ParameterStatus::kRegrouped;
  return out;
}

}  // namespace dynid::ls
