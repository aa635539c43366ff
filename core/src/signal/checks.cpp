#include "checks.hpp"

#include <cmath>
#include <string>

#include "dynid/error.hpp"

namespace dynid::signal::detail {

void require_finite(const Eigen::MatrixXd& x, Eigen::Index first_sample, const char* what) {
  for (Eigen::Index c = 0; c < x.cols(); ++c) {
    for (Eigen::Index k = 0; k < x.rows(); ++k) {
      const double v = x(k, c);
      if (!std::isfinite(v)) {
        throw InputError(std::string(what) + ": channel " + std::to_string(c) + ", sample " +
                         std::to_string(first_sample + k) + " is " +
                         (std::isnan(v) ? "NaN" : "infinite") + "; samples must be finite");
      }
    }
  }
}

void require_columns(const Eigen::MatrixXd& x, Eigen::Index channels, const char* what) {
  if (x.cols() != channels)
    throw InputError(std::string(what) + ": chunk has " + std::to_string(x.cols()) +
                     " channels (columns), expected " + std::to_string(channels));
}

void require_sample_period(double sample_period, const char* what) {
  if (!std::isfinite(sample_period) || sample_period <= 0.0)
    throw InputError(std::string(what) + ": sample period " + std::to_string(sample_period) +
                     " s must be positive and finite");
}

void require_channel_count(Eigen::Index channels, const char* what) {
  if (channels < 1)
    throw InputError(std::string(what) + ": channel count " + std::to_string(channels) +
                     " must be >= 1");
}

}  // namespace dynid::signal::detail
