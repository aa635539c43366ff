#pragma once
// The second car's models as its profile declares them (benchcar.toml: constants and effects),
// fitted on a run by the product's own code, with both of its standard deviations:
//   declared_fit  DYCARO's weighted estimate (residual::fit_model): the estimate table's std,
//                 sigma^2 (W'W)^-1, which counts every row as independent;
//   declared_hac  the same rows with HAC std (residual::hac_parameters: Newey-West on the
//                 rows' scores);
//   declared_compared  what `dynid consistency` compares (residual::compared_parameters: the
//                 HAC fit with IV's values where IV replaces least squares);
//   declared_iv   the same configuration by instrumental variables (residual::iv_fit, the run's
//                 own preprocessing setting the instruments' lag), with the Durbin-Wu-Hausman test.
// Shared by the trace benchmark (exactness checks, consistency) and the coverage benchmark.
#include <string>
#include <vector>

#include <dynid/car/vehicle_profile.hpp>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/residual/consistency.hpp"
#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::benchcar {

/// `model` with the profile's effects on `run` (segments = ingest::preprocess_offline(run)); no
/// residual series. InputError as residual::fit_model.
residual::ModelFit declared_fit(const car::VehicleProfile& profile, const std::string& model,
                                const ingest::RecordedRun& run,
                                const std::vector<ingest::PreprocessedSegment>& segments);

/// The same, preprocessing the run itself.
residual::ModelFit declared_fit(const car::VehicleProfile& profile, const std::string& model,
                                const ingest::RecordedRun& run);

/// The same fit with HAC standard deviations.
residual::ModelParameters declared_hac(const car::VehicleProfile& profile, const std::string& model,
                                       const ingest::RecordedRun& run,
                                       const std::vector<ingest::PreprocessedSegment>& segments);

/// What `dynid consistency` weighs for `model` (residual::compared_parameters).
residual::ModelParameters declared_compared(
    const car::VehicleProfile& profile, const std::string& model, const ingest::RecordedRun& run,
    const std::vector<ingest::PreprocessedSegment>& segments);

/// The same model by instrumental variables. InputError as residual::iv_fit.
residual::IvFit declared_iv(const car::VehicleProfile& profile, const std::string& model,
                            const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments);

}  // namespace dynid::benchcar
