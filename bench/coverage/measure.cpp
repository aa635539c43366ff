#include "measure.hpp"

#include <chrono>
#include <cmath>
#include <exception>
#include <string>

#include "car/clean_run.hpp"
#include "car/declared_fit.hpp"
#include "car/parameters.hpp"
#include "car/product_path.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/residual/noise_floor.hpp"
#include "dynid/residual/simex.hpp"
#include "dynid/residual/simex_against_iv.hpp"

namespace dynid::benchcoverage {
namespace {

// The model as declared, corrected by SIMEX for the noise the product measures on the run (the
// profile's declared sensors in place of their measurement), as the server would. The draws are
// seeded by the run's seed: with one seed for every run the Monte Carlo error would be common to
// all the runs of a manoeuvre, a bias of the benchmark's mean rather than a scatter.
residual::SimexFit declared_simex(const car::VehicleProfile& profile, const std::string& model,
                                  const benchcar::CleanRun& run, std::uint64_t seed, int draws) {
  const ingest::ModelSpec spec = benchcar::model_spec(profile, model);
  const auto m = model::make_model(spec.model, spec.constants);
  const ingest::RecordedRun& recorded = run.product.recorded;
  const auto noise =
      residual::measure_channel_noise(recorded, run.segments, recorded.announcement.preprocessing.channel_noise);
  residual::SimexOptions options;
  options.draws = draws;
  options.seed = seed;
  return residual::simex_fit(*m, spec.effects, recorded, run.segments, noise, options);
}

// Each parameter of one model that has a truth on this run, with both std. The parameter order
// of the two fits is the model's (one fold of the same rows), checked by name all the same.
// `label`: the model's name in the tables (a variant's, e.g. the gear inferred).
void add_model(const car::VehicleProfile& profile, const std::string& model,
               const benchcar::CleanRun& run, std::uint64_t seed, int simex_draws,
               std::vector<ParameterSample>& out, const std::string& label) {
  const residual::ModelFit fit = benchcar::declared_fit(profile, model, run.product.recorded, run.segments);
  const residual::ModelParameters hac = benchcar::declared_hac(profile, model, run.product.recorded, run.segments);
  const residual::IvFit iv = benchcar::declared_iv(profile, model, run.product.recorded, run.segments);
  const residual::SimexFit simex = declared_simex(profile, model, run, seed, simex_draws);
  const bool simex_over_iv = residual::compare_simex_with_iv(iv, simex).simex_stands;
  const residual::Publication published =
      residual::publish(fit.parameters, fit.estimate, fit.column_norms, &iv, &simex);
  const residual::Publication without_simex =
      residual::publish(fit.parameters, fit.estimate, fit.column_norms, &iv, nullptr);
  for (std::size_t i = 0; i < fit.parameters.size(); ++i) {
    const std::string& name = fit.parameters[i].name;
    const auto truth = run.truth.parameters.find(name);
    if (truth == run.truth.parameters.end()) continue;
    ParameterSample s;
    s.model = label;
    s.parameter = name;
    s.truth = truth->second;
    const auto k = static_cast<Eigen::Index>(i);
    s.value = fit.estimate.value(k);
    s.std = fit.estimate.standard_deviation(k);
    if (i < hac.parameters.size() && hac.parameters[i].name == name) {
      s.hac_value = hac.value(k);
      s.hac_std = hac.std(k);
    }
    if (i < iv.parameters.size() && iv.parameters[i].name == name) {
      s.iv_value = iv.value(k);
      s.iv_std = iv.std(k);
      s.iv_hac_std = iv.hac_std(k);
      s.iv_difference_std = iv.difference_std(k);
    }
    if (i < simex.parameters.size() && simex.parameters[i].name == name) {
      s.simex_value = simex.value(k);
      s.simex_std = simex.std(k);
      s.simex_mc_std = simex.monte_carlo_std(k);
      s.simex_level_std = simex.level_std(k);
      s.simex_corrected = simex.corrected();
    }
    s.simex_over_iv = simex_over_iv;
    if (k < published.value.size()) {
      s.published_value = published.value(k);
      s.published_std = published.std(k);
      s.published_by =
          published.replaced[i] ? published.estimator : residual::PublishedEstimator::kLeastSquares;
      s.without_simex_value = without_simex.value(k);
      s.without_simex_std = without_simex.std(k);
      s.without_simex_by = without_simex.replaced[i] ? without_simex.estimator
                                                     : residual::PublishedEstimator::kLeastSquares;
    }
    s.dwh_rejects = iv.dwh.rejects;
    s.iv_instrument_f = iv.instrument_f;
    s.iv_refused = iv.reason;
    out.push_back(s);
  }
}

// The engine model as a bus without a gear signal and without a gearbox input speed has it
// (longitudinal.hpp, the gear inferred): the car's gear ratios, gearbox times final drive, given
// as constants, so that the model reads engine_speed instead of the run's gear_ratio channel,
// and a clutch slip tolerance no slip reaches, so that the run's gearbox_input_speed masks
// nothing: the rows the inference leaves out are the only clutch mask.
car::VehicleProfile with_gear_inferred(car::VehicleProfile profile) {
  const benchcar::CarParameters car;
  for (ingest::ModelSpec& m : profile.models) {
    if (m.model != "longitudinal_engine") continue;
    for (int gear = 1; gear <= static_cast<int>(car.gearbox.size()); ++gear)
      m.constants["gear_ratio_" + std::to_string(gear)] = car.gear_ratio(gear);
    m.constants["clutch_slip_tolerance"] = 1e9;  // rad/s
  }
  return profile;
}

// The clutch as a car without a clamp-load sensor has it (clutch_torque_curve.hpp): the same
// launches through the actuator's travel, with the car's touch point, the clutch model's masks
// and viscous friction, and open_engagement at the travel of its open_clamp_load.
car::VehicleProfile with_torque_curve(car::VehicleProfile profile) {
  const benchcar::CarParameters car;
  ingest::ModelSpec spec = benchcar::model_spec(profile, "clutch_slip");
  spec.model = "clutch_torque_curve";
  spec.constants = {
      {"touch_point", car.clutch_touch_point},
      {"open_engagement", car.clutch_engagement(spec.constants.at("open_clamp_load"))},
      {"min_slip_speed", spec.constants.at("min_slip_speed")},
      {"stick_margin", spec.constants.at("stick_margin")}};
  spec.effects = {"viscous_friction"};
  profile.models.push_back(spec);
  return profile;
}

}  // namespace

double ParameterSample::relative_error() const { return (value - truth) / std::abs(truth); }

double ParameterSample::iv_relative_error() const { return (iv_value - truth) / std::abs(truth); }

double ParameterSample::simex_relative_error() const { return (simex_value - truth) / std::abs(truth); }

const std::vector<std::string>& models_of(benchcar::Manoeuvre manoeuvre) {
  static const std::vector<std::string> longitudinal = {"longitudinal_wheel", "longitudinal_engine"};
  static const std::vector<std::string> lateral = {"lateral_bicycle", "lateral_bicycle_no_vy"};
  static const std::vector<std::string> launch = {"clutch_slip"};
  static const std::vector<std::string> none;
  switch (manoeuvre) {
    case benchcar::Manoeuvre::kLongitudinal: return longitudinal;
    case benchcar::Manoeuvre::kLateral: return lateral;
    case benchcar::Manoeuvre::kLaunch: return launch;
    case benchcar::Manoeuvre::kCruise: return none;
  }
  return none;
}

SeedRun measure_seed(const car::VehicleProfile& profile, benchcar::Manoeuvre manoeuvre, std::uint64_t seed,
                     double noise_scale, const std::filesystem::path& work_dir, int simex_draws, bool mirrored) {
  const auto t0 = std::chrono::steady_clock::now();
  SeedRun r;
  r.manoeuvre = manoeuvre;
  r.seed = seed;
  r.mirrored = mirrored;
  // The mirrored run's SIMEX draws are its own: the Monte Carlo error is not odd in the run's
  // noise, so sharing the draws would not cancel it but make it common to the pair.
  const std::uint64_t simex_seed = mirrored ? ~seed : seed;
  try {
    const benchcar::CleanRun run = benchcar::clean_run(profile, manoeuvre, seed, noise_scale, work_dir, mirrored);
    for (const std::string& model : models_of(manoeuvre))
      add_model(profile, model, run, simex_seed, simex_draws, r.samples, model);
    if (manoeuvre == benchcar::Manoeuvre::kLongitudinal)
      add_model(with_gear_inferred(profile), "longitudinal_engine", run, simex_seed, simex_draws,
                r.samples, "longitudinal_engine, gear inferred");
    if (manoeuvre == benchcar::Manoeuvre::kLaunch)
      add_model(with_torque_curve(profile), "clutch_torque_curve", run, simex_seed, simex_draws,
                r.samples, "clutch_torque_curve");
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace dynid::benchcoverage
