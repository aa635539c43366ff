#pragma once
// Derivatives of sampled signals by central differences (DYCARO, venture-2003 §4.3, there of
// second order; here of fourth order inside): zero phase, so a derivative stays aligned with the
// zero-phase filtered signal it comes from.
//   inside:        x'[k]   = (x[k-2] - 8 x[k-1] + 8 x[k+1] - x[k+2]) / (12 T)   (2 <= k <= n-3)
//   next to ends:  x'[1]   = (x[2] - x[0]) / (2 T),  x'[n-2] = (x[n-1] - x[n-3]) / (2 T)
//   first, last:   x'[0]   = (-3 x[0] + 4 x[1] - x[2]) / (2 T)
//                  x'[n-1] = ( 3 x[n-1] - 4 x[n-2] + x[n-3]) / (2 T)   (second order, one-sided)
// Exact on quadratics everywhere, on quartics inside. For sin(w t) the inside has the gain
// (8 sin(wT) - sin(2 wT)) / (6 wT): 0.99967 at the default cut-off (5 Hz at 100 Hz), where the
// source's (x[k+1] - x[k-1]) / (2 T), sin(wT) / (wT), is 0.984. That 1.6 % shortfall of the
// derivative in the band the rows carry biased the parameters read through it (a yaw inertia by
// +0.06 %, the drag area at a gear shift's transient) on noise-free data. The samples next to
// the ends, where the lower orders are used, lie within the filter's edge reach, where no row is
// built (ingest::Preprocessing::edge_samples).
// Uniform sampling is assumed: T (seconds) is the one period between all samples.
// Rows are samples, columns are channels (an Eigen::VectorXd converts to one channel).
#include <Eigen/Core>

namespace dynid::signal {

// Throws InputError when T is not positive and finite, x has fewer than 3 rows, or a sample is
// NaN or infinite.
Eigen::MatrixXd derivative(const Eigen::MatrixXd& x, double sample_period);

// The inside stencil at sample k of one signal (reads x(k-2) .. x(k+2), unchecked): for a caller
// that builds one value at a time (a dictionary column, model/effects.hpp) and must give
// derivative()'s value there.
inline double inside_derivative(const Eigen::VectorXd& x, Eigen::Index k, double sample_period) {
  return (x(k - 2) - 8.0 * x(k - 1) + 8.0 * x(k + 1) - x(k + 2)) / (12.0 * sample_period);
}

// The same over chunks, two samples of look-ahead: x'[k] is returned once x[k+2] is in (x'[0]
// and x'[1] together, once x[2] is in); finish() returns x'[n-2] (if not out yet) and x'[n-1].
// Holds the last 4 samples.
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
    Eigen::MatrixXd recent;  // the last min(samples_in, 4) samples, oldest first
  };
  State state() const { return {n_in_, n_out_, finished_, recent_}; }
  // Throws InputError, leaving the object unchanged, when the state cannot be this object's.
  void restore(const State& state);

  Eigen::Index samples_in() const { return n_in_; }
  Eigen::Index samples_out() const { return n_out_; }

 private:
  Eigen::Index channels_;
  double period_;
  Eigen::MatrixXd recent_;  // the last min(samples_in, 4) samples, oldest first
  Eigen::Index n_in_ = 0;
  Eigen::Index n_out_ = 0;
  bool finished_ = false;
};

}  // namespace dynid::signal
