#pragma once
// Derivatives of sampled signals by central differences (DYCARO, venture-2003 §4.3): zero phase,
// so a derivative stays aligned with the zero-phase filtered signal it comes from.
//   inside:      x'[k]   = (x[k+1] - x[k-1]) / (2 T)
//   first, last: x'[0]   = (-3 x[0] + 4 x[1] - x[2]) / (2 T)
//                x'[n-1] = ( 3 x[n-1] - 4 x[n-2] + x[n-3]) / (2 T)   (second order, one-sided)
// Exact on quadratics. For sin(w t) the inside gives sin(w T)/T cos(w t): a gain
// sin(wT)/(wT) <= 1 that the low-pass before it keeps close to 1 in the band of interest.
// Uniform sampling is assumed: T (seconds) is the one period between all samples.
// Rows are samples, columns are channels (an Eigen::VectorXd converts to one channel).
#include <Eigen/Core>

namespace dynid::signal {

// Throws InputError when T is not positive and finite, x has fewer than 3 rows, or a sample is
// NaN or infinite.
Eigen::MatrixXd derivative(const Eigen::MatrixXd& x, double sample_period);

// The same over chunks, one sample of look-ahead: x'[k] is returned once x[k+1] is in (x'[0]
// and x'[1] together, once x[2] is in); finish() returns x'[n-1]. Holds the last 3 samples.
// Equal to derivative() of the whole signal to the bit. Errors as derivative(), and a
// rejected push()/finish() leaves the object unchanged.
class StreamingDerivative {
 public:
  StreamingDerivative(Eigen::Index channels, double sample_period);
  Eigen::MatrixXd push(const Eigen::MatrixXd& chunk);
  Eigen::MatrixXd finish();
  void reset();

  // The complete state between calls, exact (for checkpoints): restored into a derivative of the
  // same channel count and period, it continues the signal to the bit.
  struct State {
    Eigen::Index samples_in = 0;
    Eigen::Index samples_out = 0;
    bool finished = false;
    Eigen::MatrixXd recent;  // the last min(samples_in, 3) samples, oldest first
  };
  State state() const { return {n_in_, n_out_, finished_, recent_}; }
  // Throws InputError, leaving the object unchanged, when the state cannot be this object's.
  void restore(const State& state);

  Eigen::Index samples_in() const { return n_in_; }
  Eigen::Index samples_out() const { return n_out_; }

 private:
  Eigen::Index channels_;
  double period_;
  Eigen::MatrixXd recent_;  // the last min(samples_in, 3) samples, oldest first
  Eigen::Index n_in_ = 0;
  Eigen::Index n_out_ = 0;
  bool finished_ = false;
};

}  // namespace dynid::signal
