#include "dynid/signal/derivative.hpp"

#include <algorithm>
#include <string>

#include "checks.hpp"
#include "dynid/error.hpp"

namespace dynid::signal {

StreamingDerivative::StreamingDerivative(Eigen::Index channels, double sample_period)
    : channels_(channels), period_(sample_period) {
  detail::require_channel_count(channels, "StreamingDerivative");
  detail::require_sample_period(sample_period, "StreamingDerivative");
  reset();
}

void StreamingDerivative::reset() {
  recent_.resize(0, channels_);
  n_in_ = 0;
  n_out_ = 0;
  finished_ = false;
}

namespace {

// Samples held between pushes: x'[k] needs x[k-2] .. x[k+2], and the next k is samples_in - 2.
constexpr Eigen::Index kHeld = 4;

// How many x'[k] are final once `samples_in` samples are in (before finish()): x'[0] (one-sided)
// and x'[1] (three-point) once x[2] is in, x'[k >= 2] (five-point) once x[k + 2] is in.
Eigen::Index final_before_finish(Eigen::Index samples_in) {
  return samples_in >= 3 ? std::max<Eigen::Index>(2, samples_in - 2) : 0;
}

}  // namespace

Eigen::MatrixXd StreamingDerivative::push(const Eigen::MatrixXd& chunk) {
  const char* what = "StreamingDerivative::push";
  if (finished_) throw InputError(std::string(what) + ": the signal was finished; reset() first");
  detail::require_columns(chunk, channels_, what);
  detail::require_finite(chunk, n_in_, what);
  // w: the recent samples then the chunk; w.row(i) is sample first + i of the stream.
  Eigen::MatrixXd w(recent_.rows() + chunk.rows(), channels_);
  w << recent_, chunk;
  const Eigen::Index first = n_in_ - recent_.rows();
  n_in_ += chunk.rows();
  const Eigen::Index final_count = final_before_finish(n_in_);
  Eigen::MatrixXd out(final_count - n_out_, channels_);
  const double half = 0.5 / period_;
  const double twelfth = 1.0 / (12.0 * period_);
  for (Eigen::Index k = n_out_; k < final_count; ++k) {
    const Eigen::Index i = k - first;
    if (k == 0)
      out.row(0) = (-3.0 * w.row(i) + 4.0 * w.row(i + 1) - w.row(i + 2)) * half;
    else if (k == 1)
      out.row(k - n_out_) = (w.row(i + 1) - w.row(i - 1)) * half;
    else
      out.row(k - n_out_) =
          (w.row(i - 2) - 8.0 * w.row(i - 1) + 8.0 * w.row(i + 1) - w.row(i + 2)) * twelfth;
  }
  n_out_ = final_count;
  recent_ = w.bottomRows(std::min<Eigen::Index>(kHeld, w.rows()));
  return out;
}

void StreamingDerivative::restore(const State& s) {
  const Eigen::Index out = s.finished ? s.samples_in : final_before_finish(s.samples_in);
  const bool fits = s.samples_in >= 0 && s.recent.cols() == channels_ &&
                    s.recent.rows() == std::min<Eigen::Index>(kHeld, s.samples_in) &&
                    s.samples_out == out && (!s.finished || s.samples_in >= 3) && s.recent.allFinite();
  if (!fits)
    throw InputError("StreamingDerivative::restore: the state does not fit (" +
                     std::to_string(channels_) + " channels; counts, shape or values)");
  n_in_ = s.samples_in;
  n_out_ = s.samples_out;
  finished_ = s.finished;
  recent_ = s.recent;
}

Eigen::MatrixXd StreamingDerivative::finish() {
  const char* what = "StreamingDerivative::finish";
  if (finished_) throw InputError(std::string(what) + ": already finished");
  if (n_in_ < 3)
    throw InputError(std::string(what) + ": the signal has " + std::to_string(n_in_) +
                     " samples; a second-order derivative needs at least 3");
  const Eigen::Index h = recent_.rows();
  const auto last = [&](Eigen::Index back) { return recent_.row(h - 1 - back); };  // x[n-1-back]
  const double half = 0.5 / period_;
  // x'[n-2] (three-point) unless it is x'[1], out already; then x'[n-1] (one-sided).
  Eigen::MatrixXd out(n_in_ - n_out_, channels_);
  if (n_out_ == n_in_ - 2) out.row(0) = (last(0) - last(2)) * half;
  out.bottomRows(1) = (3.0 * last(0) - 4.0 * last(1) + last(2)) * half;
  n_out_ = n_in_;
  finished_ = true;
  return out;
}

Eigen::MatrixXd derivative(const Eigen::MatrixXd& x, double sample_period) {
  detail::require_sample_period(sample_period, "derivative");
  if (x.rows() < 3)
    throw InputError("derivative: the signal has " + std::to_string(x.rows()) +
                     " samples; a second-order derivative needs at least 3");
  if (x.cols() == 0) return Eigen::MatrixXd(x.rows(), 0);
  StreamingDerivative d(x.cols(), sample_period);
  Eigen::MatrixXd y(x.rows(), x.cols());
  const Eigen::MatrixXd pushed = d.push(x);
  y.topRows(pushed.rows()) = pushed;
  y.bottomRows(x.rows() - pushed.rows()) = d.finish();
  return y;
}

}  // namespace dynid::signal
