#pragma once
// The product's data path for simulated runs, shared by the accuracy and residual-loop tests:
// the simulator's can.log replayed through dynid_car_core with the test car's profile
// (deploy/profiles/testcar.toml: DBC decode, units, resampling, chunks), as dynid-car does.
// Needs DYNID_TESTCAR_PROFILE (the profile's path) defined by the test target.
#include <functional>
#include <string>
#include <vector>

#include <dynid/car/vehicle_profile.hpp>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/zero_calibration.hpp"
#include "dynid/model/constants.hpp"
#include "dynid/sim/simulator.hpp"

namespace dynid::sim::test {

const car::VehicleProfile& testcar_profile();

/// The profile's spec of a model (constants merged) with the given effects and extra constants.
/// Adds a test failure when the profile has no such model.
ingest::ModelSpec model_spec(const std::string& name, std::vector<std::string> effects,
                             const model::Constants& extra = {});

/// The run's can.log replayed with the test car's profile; every chunk goes to `sink`. Adds test
/// failures for undecodable frames or an empty run.
void replay_run(const Run& run, const std::string& run_name,
                const std::function<void(ingest::Chunk&&)>& sink);

/// All the chunks of a replayed run, in order.
std::vector<ingest::Chunk> replay_chunks(const Run& run, const std::string& run_name);

/// The zeros of the wheel-torque meter and the clamp-load sensor from a tare run (the scenario
/// `tare_scenario_text`, same seed: the same sensors) through the same path.
ingest::ZeroCalibration tare_for(const Run& run, const std::string& tare_scenario_text);

}  // namespace dynid::sim::test
