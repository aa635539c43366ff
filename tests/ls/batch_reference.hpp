#pragma once
// An independent reference for the accumulator: a batch LAPACK least-squares solve of all rows
// at once (dgels: Householder QR of the whole m x n matrix), with the textbook statistics.
#include <Eigen/Core>

namespace dynid::test {

struct BatchSolution {
  Eigen::VectorXd x;
  Eigen::VectorXd standard_deviation;
  double residual_norm = 0.0;
  double sigma = 0.0;
};

/// Full-column-rank batch solve of min ||W x - y||; throws if LAPACK reports a failure.
BatchSolution batch_solve(const Eigen::MatrixXd& W, const Eigen::VectorXd& y);

/// max_i |a_i - b_i| / max(|b|_inf, tiny): the relative error of a whole vector.
double relative_error(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

}  // namespace dynid::test
