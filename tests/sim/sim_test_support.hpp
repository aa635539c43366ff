#pragma once
// Helpers shared by the simulator's tests.
#include <string>
#include <vector>

#include <dynid/can/dbc.hpp>

#include "dynid/sim/simulator.hpp"

namespace dynid::sim::test {

// The project DBC, parsed once.
const can::Database& testcar_dbc();
// A scenario from TOML text (see scenario.hpp).
Scenario scenario(const std::string& toml);
Run run(const std::string& toml, std::uint64_t seed = 1);
// Column of one channel.
std::vector<double> column(const Run& run, const std::string& channel, bool truth = true);
// Value of a truth.toml key, e.g. "vehicle.mass".
double truth_value(const Run& run, const std::string& dotted_key);

}  // namespace dynid::sim::test

namespace dynid::sim::test {
// The text of a committed scenario (deploy/scenarios/<file>).
std::string load_scenario_text(const std::string& file);
}  // namespace dynid::sim::test
