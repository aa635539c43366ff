#include "dynid/sim/effects.hpp"

namespace dynid::sim {

std::vector<std::pair<std::string, bool*>> named_effects(Effects& e) {
  return {
      {"tyre_saturation", &e.tyre_saturation},
      {"tyre_load_sensitivity", &e.tyre_load_sensitivity},
      {"load_transfer", &e.load_transfer},
      {"aero_drag", &e.aero_drag},
      {"rolling_resistance", &e.rolling_resistance},
      {"road_grade", &e.road_grade},
      {"road_bank", &e.road_bank},
      {"anti_roll_bars", &e.anti_roll_bars},
      {"nonlinear_damping", &e.nonlinear_damping},
      {"suspension_friction", &e.suspension_friction},
      {"tyre_vertical_compliance", &e.tyre_vertical_compliance},
      {"brake_drag", &e.brake_drag},
      {"clutch_stribeck", &e.clutch_stribeck},
      {"clutch_viscous", &e.clutch_viscous},
      {"driveshaft_compliance", &e.driveshaft_compliance},
      {"sensor_noise", &e.sensor_noise},
      {"sensor_offsets", &e.sensor_offsets},
      {"quantization", &e.quantization},
  };
}

std::vector<std::pair<std::string, bool>> named_effects(const Effects& effects) {
  Effects copy = effects;
  std::vector<std::pair<std::string, bool>> out;
  for (const auto& [name, flag] : named_effects(copy)) out.emplace_back(name, *flag);
  return out;
}

}  // namespace dynid::sim
