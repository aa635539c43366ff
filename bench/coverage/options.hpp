#pragma once
// The coverage benchmark's command line (dynid-bench-coverage --help).
#include <string>
#include <vector>

#include "car/manoeuvres.hpp"

namespace dynid::benchcoverage {

struct Options {
  int seeds = 20;  ///< clean runs per manoeuvre, seeds 1001 .. 1000 + seeds
  std::vector<benchcar::Manoeuvre> manoeuvres = {benchcar::Manoeuvre::kLongitudinal, benchcar::Manoeuvre::kLateral,
                                                 benchcar::Manoeuvre::kLaunch};
  double noise_scale = 1.0;  ///< the car's sensor noise times this (0: noise-free, to tell noise from model error)
  int simex_draws = 8;  ///< SIMEX draws per lambda (residual::SimexOptions::draws)
  /// Each seed run twice, with its sensor noise and with the mirror of it (benchcar::BusOptions::
  /// mirrored): antithetic pairs, whose mean error holds the estimator's bias without the terms
  /// odd in the noise that dominate a mean over independent seeds (docs/ACCURACY.md).
  bool antithetic = false;
  std::string json;  ///< per-run values, empty: none
  std::string profile = DYNID_BENCHCAR_PROFILE;
  bool smoke = false;
};

/// Exits with status 2 and the usage on a bad argument.
Options parse_options(int argc, char** argv);

}  // namespace dynid::benchcoverage
