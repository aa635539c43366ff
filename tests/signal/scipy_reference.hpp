#pragma once
// Runs tests/signal/scipy_reference.py with Debian's interpreter (/usr/bin/python3, which has
// python3-scipy; the pyenv python3 on PATH does not) and reads its answer.
#include <Eigen/Core>
#include <optional>
#include <string>

namespace dynid::signal::test {

struct ScipyAnswer {
  Eigen::MatrixXd sos;       // butter(order, cutoff, fs=rate, output='sos')
  Eigen::MatrixXd filtered;  // sosfiltfilt(sos, x, axis=0), when a signal was given
  std::string error;         // scipy's message when it rejected the signal
};

// std::nullopt, with `why` set, when /usr/bin/python3 or scipy is not available.
std::optional<ScipyAnswer> run_scipy(int order, double cutoff_hz, double rate_hz,
                                     const Eigen::MatrixXd* x, std::string& why);

}  // namespace dynid::signal::test
