#include "dynid/signal/integrate.hpp"

#include <algorithm>

#include "checks.hpp"

namespace dynid::signal {

StreamingTrapezoid::StreamingTrapezoid(Eigen::Index channels, double sample_period)
    : channels_(channels), period_(sample_period) {
  detail::require_channel_count(channels, "StreamingTrapezoid");
  detail::require_sample_period(sample_period, "StreamingTrapezoid");
  reset();
}

void StreamingTrapezoid::reset() {
  last_.resize(0);
  sum_ = Eigen::RowVectorXd::Zero(channels_);
  n_in_ = 0;
}

Eigen::MatrixXd StreamingTrapezoid::push(const Eigen::MatrixXd& chunk) {
  const char* what = "StreamingTrapezoid::push";
  detail::require_columns(chunk, channels_, what);
  detail::require_finite(chunk, n_in_, what);
  Eigen::MatrixXd y(chunk.rows(), channels_);
  for (Eigen::Index k = 0; k < chunk.rows(); ++k) {
    if (last_.size() > 0) sum_ += 0.5 * period_ * (chunk.row(k) + last_);
    last_ = chunk.row(k);
    y.row(k) = sum_;
  }
  n_in_ += chunk.rows();
  return y;
}

Eigen::MatrixXd cumulative_trapezoid(const Eigen::MatrixXd& x, double sample_period) {
  detail::require_sample_period(sample_period, "cumulative_trapezoid");
  if (x.cols() == 0) return Eigen::MatrixXd(x.rows(), 0);
  StreamingTrapezoid integrator(x.cols(), sample_period);
  return integrator.push(x);
}

}  // namespace dynid::signal
