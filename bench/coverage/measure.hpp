#pragma once
// One seed of the coverage benchmark: a clean run of one manoeuvre (car/clean_run.hpp: the car's
// normal sensor noise, no effect injected), every model identified on that manoeuvre fitted as
// the profile declares it, and for each parameter with a known truth its value with the two
// standard deviations the product reports (car/declared_fit.hpp): the estimate table's (DYCARO's
// weighted LS) and the HAC one of `dynid consistency`; and the instrumental-variable estimate
// (residual::iv_fit) with its std and the Durbin-Wu-Hausman test against LS; and the SIMEX
// correction of LS (residual::simex_fit) for the channels' noise as the product measures it
// (measure_channel_noise, the profile's declared sensors replacing their measurement).
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <dynid/car/vehicle_profile.hpp>

#include "dynid/residual/publication.hpp"

#include "car/manoeuvres.hpp"

namespace dynid::benchcoverage {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct ParameterSample {
  std::string model;
  std::string parameter;
  double truth = kNaN;
  double value = kNaN;      ///< the estimate table's value (NaN: not identifiable)
  double std = kNaN;        ///< its std, sigma^2 (W'W)^-1
  double hac_value = kNaN;  ///< residual::hac_parameters' value (the same estimator)
  double hac_std = kNaN;
  /// Instrumental variables (residual::iv_fit) on the rows that have an instrument.
  double iv_value = kNaN;   ///< NaN: refused (iv_refused says why) or not identifiable
  double iv_std = kNaN;     ///< textbook s^2 (Z'W)^-1 Z'Z (W'Z)^-1
  double iv_hac_std = kNaN; ///< HAC sandwich
  double iv_difference_std = kNaN;  ///< HAC std of IV - LS (IvFit::difference_std)
  bool dwh_rejects = false; ///< the model's Durbin-Wu-Hausman test rejects at 1 %
  double iv_instrument_f = kNaN;  ///< the model's Cragg-Donald F (weak-instrument check)
  std::string iv_refused;   ///< the refusal's reason, empty when IV was estimated
  /// SIMEX (residual::simex_fit): LS corrected for the measured noise of the channels it reads.
  double simex_value = kNaN;
  double simex_std = kNaN;     ///< sqrt(LS HAC^2 + Monte Carlo^2 + noise level^2)
  double simex_mc_std = kNaN;  ///< its Monte Carlo part
  double simex_level_std = kNaN;  ///< its noise-level part
  bool simex_corrected = false;  ///< some channel's noise reaches the rows
  /// Hausman's comparison lets SIMEX stand in for IV (residual::compare_simex_with_iv, the model's
  /// fits as a whole): published in IV's place where DWH rejects least squares.
  bool simex_over_iv = false;
  /// What the product publishes (residual::publish, the server's rule) with both fits, and with
  /// the IV fit alone (the rule before SIMEX): value, std and the estimator that gave them.
  double published_value = kNaN;
  double published_std = kNaN;
  residual::PublishedEstimator published_by = residual::PublishedEstimator::kLeastSquares;
  double without_simex_value = kNaN;
  double without_simex_std = kNaN;
  residual::PublishedEstimator without_simex_by = residual::PublishedEstimator::kLeastSquares;
  /// (value - truth) / |truth|: relative, so that a negative truth (the clutch's viscous slope)
  /// keeps the error's sign.
  double relative_error() const;
  double iv_relative_error() const;
  double simex_relative_error() const;
};

struct SeedRun {
  benchcar::Manoeuvre manoeuvre = benchcar::Manoeuvre::kLongitudinal;
  std::uint64_t seed = 0;
  bool mirrored = false;  ///< the seed's noise with every draw's sign flipped (--antithetic)
  double seconds = 0.0;
  std::string error;  ///< non-empty: the run or a fit failed (InputError text)
  std::vector<ParameterSample> samples;
};

/// The models identified on a manoeuvre (docs/RESIDUAL.md "Benchmark on a second car").
const std::vector<std::string>& models_of(benchcar::Manoeuvre manoeuvre);

/// One clean run at `seed` (sensor noise times noise_scale, its draws' signs flipped when
/// `mirrored`) and its fits, SIMEX with `simex_draws` draws per lambda. Never throws: a failure
/// is SeedRun::error.
SeedRun measure_seed(const car::VehicleProfile& profile, benchcar::Manoeuvre manoeuvre, std::uint64_t seed,
                     double noise_scale, const std::filesystem::path& work_dir, int simex_draws = 8,
                     bool mirrored = false);

}  // namespace dynid::benchcoverage
