#pragma once
// Scenario: everything one simulated run depends on besides the seed, read from a TOML file.
//
// Format (every key optional; defaults are the reference car and a straight run):
//   [run]        name, duration (s), internal_rate (Hz, RK4), output_rate (Hz, CSV grid),
//                seed (default when the command gives none), start_timestamp (s, CAN log
//                clock), interface ("can0"), noise_scale (multiplies every sensor noise)
//   [manoeuvre]  type = "straight" | "sine_steer" | "step_steer" | "spiral" | "lift_off" |
//                "acceleration" | "coast_down" | "launch", and the ManoeuvreSpec fields by
//                name (speed, gear, start_time, amplitude, ...; see manoeuvre.hpp)
//   [effects]    the Effects switches by name (effects.hpp), true/false
//   [road]       grade = [[distance_m, rad], ...], bank = [[distance_m, rad], ...]
//   [vehicle] / [driveline]   any parameter of parameters.hpp by its field name
//   [sensor_gain] <channel> = gain: that sensor reads gain x the truth (a calibration error that
//                only a second model or a reference value can reveal)
// Contract: unknown tables or keys, wrong types and out-of-range values throw InputError naming
// the file, the key and the reason (a typo must not silently run the default).
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

#include "dynid/sim/car_model.hpp"
#include "dynid/sim/manoeuvre.hpp"

namespace dynid::sim {

struct Scenario {
  std::string name = "straight";
  double duration = 20.0;
  double internal_rate = 1000.0;
  double output_rate = 100.0;
  std::uint64_t seed = 1;
  double start_timestamp = 1700000000.0;
  std::string interface_name = "can0";
  double noise_scale = 1.0;
  std::map<std::string, double> sensor_gains;  // channel -> gain, 1 when absent
  CarParameters car = default_parameters();
  Effects effects;
  Road road;
  ManoeuvreSpec manoeuvre;
};

Scenario parse_scenario(std::string_view toml_text, std::string_view source_name);
Scenario load_scenario(const std::filesystem::path& path);

}  // namespace dynid::sim
