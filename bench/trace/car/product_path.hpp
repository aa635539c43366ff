#pragma once
// The product's data path for the second car, as dynid-car runs it: the simulated can.log
// replayed through dynid_car_core (CandumpSource -> CarPipeline with bench/trace/benchcar.toml:
// DBC decoding, unit conversion, resampling onto the grid, chunks), the chunks assembled into
// the run the server stores (ingest::assemble_run). Nothing of tools/sim is used.
#include <filesystem>
#include <string>

#include <dynid/car/replay.hpp>
#include <dynid/car/vehicle_profile.hpp>

#include "dynid/ingest/recorded_run.hpp"
#include "perturbation.hpp"
#include "sensors.hpp"
#include "truth.hpp"

namespace dynid::benchcar {

/// The profile at `path`, loaded once (later calls return the first one).
const car::VehicleProfile& profile(const std::filesystem::path& path = {});

/// The profile's spec of a model, its constants merged. InputError for a model it lacks.
ingest::ModelSpec model_spec(const car::VehicleProfile& profile, const std::string& model);

struct ProductRun {
  ingest::RecordedRun recorded;
  car::ReplayProgress progress;
};

/// Simulated truth -> sensors -> can.log (in `work_dir`, removed after) -> replay -> chunks ->
/// assembled run. InputError when the replay drops frames (bad or unknown) or yields no row.
ProductRun through_product(const car::VehicleProfile& profile, const Truth& truth, const Perturbation& perturbation,
                           const BusOptions& bus, const std::string& run_name,
                           const std::filesystem::path& work_dir);

}  // namespace dynid::benchcar
