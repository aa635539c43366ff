#include "dynid/sim/parameters.hpp"

namespace dynid::sim {

double VehicleParameters::static_tyre_load(int corner) const {
  // The whole car's CG is at O: each axle carries the share its distance to the other gives.
  const double axle = corner < 2 ? cg_to_rear_axle : cg_to_front_axle;
  return 0.5 * mass * kGravity * axle / wheelbase();
}

double VehicleParameters::static_spring_force(int corner) const {
  return static_tyre_load(corner) - unsprung_mass(corner) * kGravity;
}

double DrivelineParameters::ratio(int gear) const {
  if (gear <= 0 || gear > gear_count()) return 0.0;
  return gear_ratios[static_cast<std::size_t>(gear - 1)];
}

double DrivelineParameters::input_side_inertia(int gear) const {
  const double a = ratio(gear);
  return a > 0.0 ? gearbox_input_inertia + 2.0 * driveshaft_inertia / (a * a) : gearbox_input_inertia;
}

CarParameters default_parameters() { return CarParameters{}; }

std::vector<std::pair<std::string, double*>> named_parameters(CarParameters& car) {
  auto& v = car.vehicle;
  auto& d = car.driveline;
  return {
      {"vehicle.mass", &v.mass},
      {"vehicle.unsprung_mass_front", &v.unsprung_mass_front},
      {"vehicle.unsprung_mass_rear", &v.unsprung_mass_rear},
      {"vehicle.yaw_inertia", &v.yaw_inertia},
      {"vehicle.roll_inertia", &v.roll_inertia},
      {"vehicle.pitch_inertia", &v.pitch_inertia},
      {"vehicle.cg_to_front_axle", &v.cg_to_front_axle},
      {"vehicle.cg_to_rear_axle", &v.cg_to_rear_axle},
      {"vehicle.track_front", &v.track_front},
      {"vehicle.track_rear", &v.track_rear},
      {"vehicle.cg_height", &v.cg_height},
      {"vehicle.aero_height", &v.aero_height},
      {"vehicle.head_wind", &v.head_wind},
      {"vehicle.wheel_radius", &v.wheel_radius},
      {"vehicle.wheel_inertia", &v.wheel_inertia},
      {"vehicle.cornering_stiffness_front", &v.cornering_stiffness_front},
      {"vehicle.cornering_stiffness_rear", &v.cornering_stiffness_rear},
      {"vehicle.tyre_load_sensitivity", &v.tyre_load_sensitivity},
      {"vehicle.tyre_friction", &v.tyre_friction},
      {"vehicle.tyre_vertical_stiffness", &v.tyre_vertical_stiffness},
      {"vehicle.spring_front", &v.spring_front},
      {"vehicle.spring_rear", &v.spring_rear},
      {"vehicle.damping_front", &v.damping_front},
      {"vehicle.damping_rear", &v.damping_rear},
      {"vehicle.damping_quadratic_front", &v.damping_quadratic_front},
      {"vehicle.damping_quadratic_rear", &v.damping_quadratic_rear},
      {"vehicle.suspension_friction", &v.suspension_friction},
      {"vehicle.suspension_friction_speed", &v.suspension_friction_speed},
      {"vehicle.arb_front", &v.arb_front},
      {"vehicle.arb_rear", &v.arb_rear},
      {"vehicle.scx", &v.scx},
      {"vehicle.air_density", &v.air_density},
      {"vehicle.rolling_resistance", &v.rolling_resistance},
      {"vehicle.brake_drag_torque", &v.brake_drag_torque},
      {"vehicle.brake_gain_front", &v.brake_gain_front},
      {"vehicle.brake_gain_rear", &v.brake_gain_rear},
      {"vehicle.steering_ratio", &v.steering_ratio},
      {"vehicle.imu_x", &v.imu_position[0]},
      {"vehicle.imu_y", &v.imu_position[1]},
      {"vehicle.imu_z", &v.imu_position[2]},
      {"driveline.engine_inertia", &d.engine_inertia},
      {"driveline.gearbox_input_inertia", &d.gearbox_input_inertia},
      {"driveline.driveshaft_inertia", &d.driveshaft_inertia},
      {"driveline.driveshaft_stiffness", &d.driveshaft_stiffness},
      {"driveline.driveshaft_damping", &d.driveshaft_damping},
      {"driveline.clutch_radius", &d.clutch_radius},
      {"driveline.clutch_mu_static", &d.clutch_mu_static},
      {"driveline.clutch_mu_coulomb", &d.clutch_mu_coulomb},
      {"driveline.clutch_mu_viscous", &d.clutch_mu_viscous},
      {"driveline.clutch_stribeck_speed", &d.clutch_stribeck_speed},
      {"driveline.clutch_max_clamp_load", &d.clutch_max_clamp_load},
      {"driveline.engine_max_torque", &d.engine_max_torque},
      {"driveline.engine_idle_speed", &d.engine_idle_speed},
      {"driveline.idle_governor_gain", &d.idle_governor_gain},
      {"driveline.engine_drag_constant", &d.engine_drag_constant},
      {"driveline.engine_drag_viscous", &d.engine_drag_viscous},
      {"driveline.gearbox_drag", &d.gearbox_drag},
  };
}

}  // namespace dynid::sim
