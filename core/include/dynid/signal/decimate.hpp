#pragma once
// Decimation by an integer factor r: keeps samples 0, r, 2r, ... . No filtering here: low-pass
// first (zero_phase_filter at dycaro_cutoff(fs, r), i.e. 0.8 of the new Nyquist frequency),
// or the discarded samples alias into the kept band. The new sample period is r T.
// Rows are samples, columns are channels (an Eigen::VectorXd converts to one channel).
#include <Eigen/Core>

namespace dynid::signal {

// Throws InputError when factor < 1.
Eigen::MatrixXd decimate(const Eigen::MatrixXd& x, Eigen::Index factor);

// The same over chunks: keeps the samples whose index in the whole stream is a multiple of r.
class StreamingDecimator {
 public:
  explicit StreamingDecimator(Eigen::Index factor);
  Eigen::MatrixXd push(const Eigen::MatrixXd& chunk);
  void reset() { n_in_ = 0; }

 private:
  Eigen::Index factor_;
  Eigen::Index n_in_ = 0;
};

}  // namespace dynid::signal
