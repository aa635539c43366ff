#include "dynid/signal/decimate.hpp"

#include <string>

#include "dynid/error.hpp"

namespace dynid::signal {

StreamingDecimator::StreamingDecimator(Eigen::Index factor) : factor_(factor) {
  if (factor < 1) throw InputError("decimate: factor " + std::to_string(factor) + " must be >= 1");
}

Eigen::MatrixXd StreamingDecimator::push(const Eigen::MatrixXd& chunk) {
  // First kept row of this chunk: the next multiple of the factor in stream indices.
  const Eigen::Index first = (factor_ - n_in_ % factor_) % factor_;
  const Eigen::Index kept = first < chunk.rows() ? (chunk.rows() - first - 1) / factor_ + 1 : 0;
  Eigen::MatrixXd y(kept, chunk.cols());
  for (Eigen::Index i = 0; i < kept; ++i) y.row(i) = chunk.row(first + i * factor_);
  n_in_ += chunk.rows();
  return y;
}

Eigen::MatrixXd decimate(const Eigen::MatrixXd& x, Eigen::Index factor) {
  return StreamingDecimator(factor).push(x);
}

}  // namespace dynid::signal
