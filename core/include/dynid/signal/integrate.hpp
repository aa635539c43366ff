#pragma once
// Cumulative integration by the trapezoidal rule (DYCARO, venture-2003 §4.3, L1709):
//   y[0] = 0,  y[k] = y[k-1] + (T / 2) (x[k] + x[k-1]).
// Exact on linear functions. Uniform sampling is assumed: T (seconds) is the one period between
// all samples. Rows are samples, columns are channels (a VectorXd converts to one channel); the
// output has the input's shape.
#include <Eigen/Core>

namespace dynid::signal {

// Throws InputError when T is not positive and finite or a sample is NaN or infinite.
Eigen::MatrixXd cumulative_trapezoid(const Eigen::MatrixXd& x, double sample_period);

// The same over chunks, no delay: push() returns one output row per input row, equal to the
// whole-signal result to the bit. Holds the last sample and the running sums.
class StreamingTrapezoid {
 public:
  StreamingTrapezoid(Eigen::Index channels, double sample_period);
  // Throws InputError (object unchanged) on a wrong column count or a NaN/infinite sample.
  Eigen::MatrixXd push(const Eigen::MatrixXd& chunk);
  void reset();

 private:
  Eigen::Index channels_;
  double period_;
  Eigen::RowVectorXd last_;  // last input sample (empty before the first)
  Eigen::RowVectorXd sum_;
  Eigen::Index n_in_ = 0;
};

}  // namespace dynid::signal
