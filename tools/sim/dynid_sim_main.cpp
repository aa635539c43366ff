// dynid-sim: runs one scenario of the reference simulator and writes its files.
//   dynid-sim --scenario deploy/scenarios/sine_steer.toml --seed 3 --out DIR
#include <CLI/CLI.hpp>
#include <cstdint>
#include <exception>
#include <iostream>
#include <optional>
#include <string>

#include <dynid/can/dbc.hpp>

#include "dynid/sim/outputs.hpp"

int main(int argc, char** argv) {
  CLI::App app{"dynid reference simulator: a car with known parameters, its channels, truth and CAN log"};
  std::string scenario_path;
  std::string out_dir;
  std::string dbc_path = DYNID_DEFAULT_DBC;
  std::optional<std::uint64_t> seed;
  app.add_option("--scenario", scenario_path, "scenario TOML file")->required()->check(CLI::ExistingFile);
  app.add_option("--out", out_dir, "output folder (channels.csv, channels_true.csv, truth.toml, can.log)")
      ->required();
  app.add_option("--seed", seed, "random seed (default: the scenario's run.seed)");
  app.add_option("--dbc", dbc_path, "the car's DBC")->check(CLI::ExistingFile);
  CLI11_PARSE(app, argc, argv);
  try {
    const auto scenario = dynid::sim::load_scenario(scenario_path);
    const auto dbc = dynid::can::parse_dbc_file(dbc_path);
    const auto run = dynid::sim::simulate(scenario, seed.value_or(scenario.seed), dbc);
    dynid::sim::write_run(out_dir, run);
    std::cout << "dynid-sim: " << scenario.name << ", seed " << run.seed << ": " << run.time.size()
              << " samples, " << run.frames.size() << " CAN frames -> " << out_dir << '\n';
  } catch (const std::exception& e) {
    std::cerr << "dynid-sim: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
