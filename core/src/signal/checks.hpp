#pragma once
// Input checks shared by the signal functions; each throws InputError naming `what` and the
// offending value, before anything is changed.
#include <Eigen/Core>

namespace dynid::signal::detail {

// Names the channel (column) and the sample index (first_sample + row) of the first NaN or
// infinite value of x.
void require_finite(const Eigen::MatrixXd& x, Eigen::Index first_sample, const char* what);

void require_columns(const Eigen::MatrixXd& x, Eigen::Index channels, const char* what);

void require_sample_period(double sample_period, const char* what);

void require_channel_count(Eigen::Index channels, const char* what);

}  // namespace dynid::signal::detail
