#pragma once
// Effects: which physical and sensor effects the simulation includes. Each switch turns exactly
// one effect off, so a test (or the residual loop) can show what that one effect does.
//
// Contract: with a switch off the effect's term is absent from the equations (not scaled
// down), and the truth file reports the effect's parameter as 0. Exceptions, named here because
// they cannot be absent: `driveshaft_compliance` off makes the shafts 30x stiffer (a rigid shaft
// has no state in this formulation); `tyre_vertical_compliance` off slaves the wheel to the
// road (the tyre load is then the suspension force plus the unsprung weight).
#include <string>
#include <utility>
#include <vector>

namespace dynid::sim {

struct Effects {
  // Car.
  bool tyre_saturation = true;          // Fiala with friction limit; off: linear tyre
  bool tyre_load_sensitivity = true;    // cornering stiffness degressive in the load
  bool load_transfer = true;            // tyre forces see dynamic loads; off: static loads
  bool aero_drag = true;
  bool rolling_resistance = true;
  bool road_grade = true;               // the scenario's grade profile (if any)
  bool road_bank = true;                // the scenario's bank profile (if any)
  bool anti_roll_bars = true;
  bool nonlinear_damping = true;        // |v| v damper term
  bool suspension_friction = true;      // smoothed dry friction
  bool tyre_vertical_compliance = true;
  bool brake_drag = true;
  // Driveline.
  bool clutch_stribeck = true;          // off: mu_static = mu_coulomb (no Stribeck hump)
  bool clutch_viscous = true;
  bool driveshaft_compliance = true;
  // Sensors.
  bool sensor_noise = true;
  bool sensor_offsets = true;
  bool quantization = true;             // values pass through the DBC's resolution
};

// Every switch by name, for scenario files and the truth file.
std::vector<std::pair<std::string, bool*>> named_effects(Effects& effects);
std::vector<std::pair<std::string, bool>> named_effects(const Effects& effects);

}  // namespace dynid::sim
