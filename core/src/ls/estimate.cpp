#include "dynid/ls/estimate.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "dynid/error.hpp"

namespace dynid::ls {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using Extended = Accumulator::Extended;
using ExtendedMatrix = Accumulator::ExtendedMatrix;
using ExtendedVector = Eigen::Matrix<Extended, Eigen::Dynamic, 1>;

// The base-parameter subproblem: the QR of [R(:, base) D^-1 | z] (columns scaled to unit norm,
// which costs nothing and keeps the triangular solve well scaled), reduced to (k+1) x (k+1).
// Solved in the accumulator's extended precision so no digit kept there is lost here.
struct ReducedProblem {
  ExtendedMatrix t;      // upper triangular, (k+1) x (k+1); last column = [z_B; rho]
  ExtendedVector scale;  // column norms D of the base columns
};

ReducedProblem reduce(const ExtendedMatrix& r_aug, const std::vector<Eigen::Index>& base) {
  const Eigen::Index n = r_aug.cols() - 1;
  const auto k = static_cast<Eigen::Index>(base.size());
  ExtendedMatrix m(n + 1, k + 1);
  ReducedProblem p{ExtendedMatrix(), ExtendedVector(k)};
  for (Eigen::Index i = 0; i < k; ++i) {
    p.scale(i) = r_aug.col(base[static_cast<std::size_t>(i)]).norm();
    m.col(i) = r_aug.col(base[static_cast<std::size_t>(i)]) / p.scale(i);
  }
  m.col(k) = r_aug.col(n);
  Eigen::HouseholderQR<ExtendedMatrix> qr(m);
  p.t = qr.matrixQR().topRows(k + 1).triangularView<Eigen::Upper>();
  return p;
}

double condition_number(const ReducedProblem& p, Eigen::Index k) {
  if (k == 0) return kNaN;
  const Eigen::MatrixXd r_base = (p.t.topLeftCorner(k, k) * p.scale.asDiagonal()).cast<double>();
  const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(r_base).singularValues();
  return s(0) / s(k - 1);
}

}  // namespace

Estimate estimate(const Accumulator& accumulator, const EstimateOptions& options) {
  if (accumulator.row_count() == 0) throw InputError("estimate: no rows folded yet");
  const Eigen::Index n = accumulator.parameter_count();
  const ExtendedMatrix& r_aug = accumulator.augmented_r_extended();

  Estimate e;
  e.rows = accumulator.row_count();
  e.effective_rows = accumulator.effective_row_count();
  e.structure = analyse_base_parameters(r_aug.topLeftCorner(n, n).cast<double>(), e.effective_rows,
                                        options.base);
  const Eigen::Index k = e.structure.rank();
  const ReducedProblem p = reduce(r_aug, e.structure.base);
  const auto t11 = p.t.topLeftCorner(k, k).triangularView<Eigen::Upper>();

  e.residual_norm = static_cast<double>(std::abs(p.t(k, k)));
  e.degrees_of_freedom = e.effective_rows - static_cast<double>(k);
  e.sigma = e.degrees_of_freedom > 0 ? e.residual_norm / std::sqrt(e.degrees_of_freedom) : kNaN;
  const double measured = accumulator.measured_norm();
  e.relative_residual_norm = measured > 0 ? e.residual_norm / measured : kNaN;
  e.residual_rms = e.residual_norm / std::sqrt(e.effective_rows);
  e.condition_number = condition_number(p, k);

  // Base values and covariance in the scaled variables, then back: x = D^-1 x_scaled.
  const Eigen::VectorXd x_base =
      t11.solve(p.t.col(k).head(k)).cwiseQuotient(p.scale).cast<double>();
  const ExtendedMatrix t_inv = t11.solve(ExtendedMatrix::Identity(k, k));
  const ExtendedVector inv_scale = p.scale.cwiseInverse();
  const Extended sigma2 =
      p.t(k, k) * p.t(k, k) / static_cast<Extended>(e.degrees_of_freedom);  // NaN when dof <= 0
  const Eigen::MatrixXd cov_base =
      (sigma2 * inv_scale.asDiagonal() * (t_inv * t_inv.transpose()) * inv_scale.asDiagonal())
          .cast<double>();

  e.value = Eigen::VectorXd::Constant(n, kNaN);
  e.standard_deviation = Eigen::VectorXd::Constant(n, kNaN);
  e.covariance = Eigen::MatrixXd::Constant(n, n, kNaN);
  for (Eigen::Index i = 0; i < k; ++i) {
    const Eigen::Index ci = e.structure.base[static_cast<std::size_t>(i)];
    e.value(ci) = x_base(i);
    e.standard_deviation(ci) = std::sqrt(cov_base(i, i));
    for (Eigen::Index j = 0; j < k; ++j)
      e.covariance(ci, e.structure.base[static_cast<std::size_t>(j)]) = cov_base(i, j);
  }
  e.relative_std_percent = 100.0 * e.standard_deviation.array() / e.value.array().abs();
  return e;
}

}  // namespace dynid::ls
