#pragma once
// The simulated truth of one run at the integration rate: every catalogue channel the second
// car's sensors measure (docs/CHANNELS.md names and SI units), before any sensor error.
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace dynid::benchcar {

struct Truth {
  double rate_hz = 1000.0;
  std::vector<double> time;
  std::map<std::string, std::vector<double>> channels;  ///< catalogue name -> samples
  /// Parameter values of the car as the models name them (mass, SCx, ...), where a model's
  /// parameter has a single true value on this run.
  std::map<std::string, double> parameters;
  /// When a perturbation changes a parameter mid-run (a step), the time it does, s; NaN if none.
  double change_time_s = std::numeric_limits<double>::quiet_NaN();

  std::vector<double>& operator[](const std::string& name) { return channels[name]; }
  /// Linear interpolation of a channel at time t (clamped at the ends).
  double at(const std::string& name, double t) const;
};

}  // namespace dynid::benchcar
