#include "batch_reference.hpp"

#include <lapacke.h>

#include <Eigen/QR>
#include <stdexcept>
#include <string>

namespace dynid::test {

BatchSolution batch_solve(const Eigen::MatrixXd& W, const Eigen::VectorXd& y) {
  const auto m = static_cast<lapack_int>(W.rows());
  const auto n = static_cast<lapack_int>(W.cols());
  Eigen::MatrixXd a = W;
  Eigen::VectorXd b = y;
  lapack_int info = LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', m, n, 1, a.data(), m, b.data(), m);
  if (info != 0) throw std::runtime_error("dgels failed: info " + std::to_string(info));
  BatchSolution s;
  s.x = b.head(n);
  s.residual_norm = (W * s.x - y).norm();
  s.sigma = s.residual_norm / std::sqrt(static_cast<double>(m - n));
  // a now holds the batch R: C = sigma^2 R^-1 R^-T.
  const Eigen::MatrixXd r = a.topRows(n).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inv =
      r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(n, n));
  s.standard_deviation = s.sigma * (r_inv * r_inv.transpose()).diagonal().cwiseSqrt();
  return s;
}

double relative_error(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double scale = std::max(b.cwiseAbs().maxCoeff(), 1e-300);
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

}  // namespace dynid::test
