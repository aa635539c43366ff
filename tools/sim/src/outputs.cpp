#include "dynid/sim/outputs.hpp"

#include <cstdio>
#include <fstream>

#include <dynid/can/candump.hpp>

#include "dynid/error.hpp"

namespace dynid::sim {
namespace {

std::ofstream open_for_writing(const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw InputError(path.string() + ": cannot open for writing");
  return out;
}

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

toml::table vehicle_truth(const Scenario& sc) {
  const auto& v = sc.car.vehicle;
  const auto& fx = sc.effects;
  const double l = v.wheelbase();
  const double cf = 2.0 * v.cornering_stiffness_front;
  const double cr = 2.0 * v.cornering_stiffness_rear;
  const double rr = fx.rolling_resistance ? v.rolling_resistance : 0.0;
  const double scx = fx.aero_drag ? v.scx : 0.0;
  const double brake_drag = fx.brake_drag ? v.brake_drag_torque : 0.0;
  return toml::table{
      {"mass", v.mass},
      {"sprung_mass", v.sprung_mass()},
      {"unsprung_mass_front", v.unsprung_mass_front},
      {"unsprung_mass_rear", v.unsprung_mass_rear},
      {"longitudinal_equivalent_mass", v.longitudinal_equivalent_mass()},
      {"yaw_inertia", v.yaw_inertia},
      {"roll_inertia_sprung", v.roll_inertia},
      {"pitch_inertia_sprung", v.pitch_inertia},
      {"cg_to_front_axle", v.cg_to_front_axle},
      {"cg_to_rear_axle", v.cg_to_rear_axle},
      {"wheelbase", l},
      {"track_front", v.track_front},
      {"track_rear", v.track_rear},
      {"cg_height", v.cg_height},
      {"wheel_radius", v.wheel_radius},
      {"wheel_inertia", v.wheel_inertia},
      {"steering_ratio", v.steering_ratio},
      {"imu_position", toml::array{v.imu_position[0], v.imu_position[1], v.imu_position[2]}},
      {"cornering_stiffness_front", cf},
      {"cornering_stiffness_rear", cr},
      {"understeer_gradient", v.mass / l * (v.cg_to_rear_axle / cf - v.cg_to_front_axle / cr)},
      {"tyre_friction", v.tyre_friction},
      {"tyre_load_sensitivity", fx.tyre_load_sensitivity ? v.tyre_load_sensitivity : 0.0},
      {"scx", scx},
      {"air_density", v.air_density},
      {"aero_coefficient", 0.5 * v.air_density * scx},
      {"rolling_resistance_coefficient", rr},
      {"rolling_resistance_force", rr * v.mass * kGravity},
      {"brake_drag_torque_per_wheel", brake_drag},
      {"brake_drag_force", 4.0 * brake_drag / v.wheel_radius},
      {"road_load_constant_force", rr * v.mass * kGravity + 4.0 * brake_drag / v.wheel_radius},
      {"brake_gain_front", v.brake_gain_front},
      {"brake_gain_rear", v.brake_gain_rear},
      {"anti_roll_bar_front", fx.anti_roll_bars ? v.arb_front : 0.0},
      {"anti_roll_bar_rear", fx.anti_roll_bars ? v.arb_rear : 0.0},
      {"anti_roll_bar_front_roll", fx.anti_roll_bars ? v.arb_front * v.track_front * v.track_front : 0.0},
      {"anti_roll_bar_rear_roll", fx.anti_roll_bars ? v.arb_rear * v.track_rear * v.track_rear : 0.0},
  };
}

toml::table suspension_truth(const Scenario& sc) {
  const auto& v = sc.car.vehicle;
  const auto& fx = sc.effects;
  toml::table t;
  for (int i = 0; i < kCorners; ++i) {
    const bool front = i < 2;
    t.insert(kCornerNames[static_cast<std::size_t>(i)],
             toml::table{
                 {"stiffness", front ? v.spring_front : v.spring_rear},
                 {"damping", front ? v.damping_front : v.damping_rear},
                 {"damping_quadratic",
                  fx.nonlinear_damping ? (front ? v.damping_quadratic_front : v.damping_quadratic_rear) : 0.0},
                 {"dry_friction", fx.suspension_friction ? v.suspension_friction : 0.0},
                 {"dry_friction_speed", v.suspension_friction_speed},
                 {"static_force", v.static_spring_force(i)},
                 {"anti_roll_bar", fx.anti_roll_bars ? (front ? v.arb_front : v.arb_rear) : 0.0},
                 {"tyre_vertical_stiffness", v.tyre_vertical_stiffness},
                 {"tyre_static_load", v.static_tyre_load(i)},
             });
  }
  return t;
}

toml::table driveline_truth(const Scenario& sc, double shaft_stiffness, double shaft_damping) {
  const auto& d = sc.car.driveline;
  const auto& fx = sc.effects;
  const double mu_s = fx.clutch_stribeck ? d.clutch_mu_static : d.clutch_mu_coulomb;
  const double mu_v = fx.clutch_viscous ? d.clutch_mu_viscous : 0.0;
  toml::array ratios;
  for (double r : d.gear_ratios) ratios.push_back(r);
  return toml::table{
      {"engine_inertia", d.engine_inertia},
      {"gearbox_input_inertia", d.gearbox_input_inertia},
      {"driveshaft_inertia_each", d.driveshaft_inertia},
      {"driveshaft_stiffness_total", shaft_stiffness},
      {"driveshaft_damping_total", shaft_damping},
      {"gear_ratios", ratios},
      {"engine_idle_speed", d.engine_idle_speed},
      {"clutch", toml::table{
                     {"effective_radius", d.clutch_radius},
                     {"mu_coulomb", d.clutch_mu_coulomb},
                     {"mu_static", mu_s},
                     {"mu_viscous", mu_v},
                     {"stribeck_speed", d.clutch_stribeck_speed},
                     {"stribeck_exponent", 2.0},
                     // Torque per newton of clamp load: the levels a model with the clamp load
                     // as its regressor identifies (m, m, m s/rad).
                     {"coulomb_level", d.clutch_mu_coulomb * d.clutch_radius},
                     {"stribeck_level", (mu_s - d.clutch_mu_coulomb) * d.clutch_radius},
                     {"static_level", mu_s * d.clutch_radius},
                     {"viscous_level", mu_v * d.clutch_radius},
                 }},
  };
}

// Locked driveline per gear, reduced to the gearbox input (= engine) speed (borsotto eq. 4.14,
// 4.15c): J dw = T_e - (p + q w + r w^2), with J = J_m + J1 + 2 J_t/a^2 + M_eq R^2/a^2.
toml::table gears_truth(const Scenario& sc) {
  const auto& v = sc.car.vehicle;
  const auto& d = sc.car.driveline;
  const auto& fx = sc.effects;
  const double rr = fx.rolling_resistance ? v.rolling_resistance * v.mass * kGravity : 0.0;
  const double bd = fx.brake_drag ? 4.0 * v.brake_drag_torque / v.wheel_radius : 0.0;
  const double aero = fx.aero_drag ? 0.5 * v.air_density * v.scx : 0.0;
  const double r = v.wheel_radius;
  toml::table t;
  for (int g = 1; g <= d.gear_count(); ++g) {
    const double a = d.ratio(g);
    const double j_bv = d.input_side_inertia(g) + v.longitudinal_equivalent_mass() * r * r / (a * a);
    t.insert(std::to_string(g), toml::table{
                                    {"ratio", a},
                                    {"inertia_at_gearbox_input", j_bv},
                                    {"inertia_at_engine", d.engine_inertia + j_bv},
                                    {"road_load_p", (rr + bd) * r / a},
                                    {"road_load_q", 0.0},
                                    {"road_load_r", aero * r * r * r / (a * a * a)},
                                });
  }
  return t;
}

}  // namespace

void write_channels_csv(const std::filesystem::path& path, const Run& run, bool true_values) {
  auto out = open_for_writing(path);
  out << "time";
  for (const auto& c : run.channels) out << ',' << c.name;
  out << '\n';
  const auto& rows = true_values ? run.truth : run.measured;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    out << number(run.time[k]);
    for (double x : rows[k]) out << ',' << number(x);
    out << '\n';
  }
  if (!out) throw InputError(path.string() + ": write failed");
}

void write_can_log(const std::filesystem::path& path, const Run& run) {
  auto out = open_for_writing(path);
  can::CandumpWriter writer(out);
  for (const auto& f : run.frames) writer.write(f);
  if (!out) throw InputError(path.string() + ": write failed");
}

toml::table truth_table(const Run& run) {
  const Scenario& sc = run.scenario;
  const CarModel model{sc.car, sc.effects, sc.road};
  toml::table effects;
  for (const auto& [name, on] : named_effects(sc.effects)) effects.insert(name, on);
  toml::table offsets;
  for (std::size_t c = 0; c < run.channels.size(); ++c)
    if (run.offsets[c] != 0.0) offsets.insert(run.channels[c].name, run.offsets[c]);
  toml::table units;
  for (const auto& c : run.channels) units.insert(c.name, c.unit);
  return toml::table{
      {"run", toml::table{{"scenario", sc.name},
                          {"manoeuvre", to_string(sc.manoeuvre.type)},
                          {"seed", static_cast<std::int64_t>(run.seed)},
                          {"duration", sc.duration},
                          {"internal_rate", sc.internal_rate},
                          {"output_rate", sc.output_rate},
                          {"clutch_locks", run.statistics.clutch_locks},
                          {"clutch_unlocks", run.statistics.clutch_unlocks},
                          {"clutch_slipping_time", run.statistics.slipping_time},
                          {"max_abs_ay", run.statistics.max_lateral_slip}}},
      {"vehicle", vehicle_truth(sc)},
      {"suspension", suspension_truth(sc)},
      {"driveline", driveline_truth(sc, model.shaft_stiffness(), model.shaft_damping())},
      {"gear", gears_truth(sc)},
      {"effects", effects},
      {"sensor_offsets", offsets},
      {"channel_units", units},
  };
}

void write_truth(const std::filesystem::path& path, const Run& run) {
  auto out = open_for_writing(path);
  out << "# dynid reference simulator: the parameters of the simulated car, SI units.\n"
      << "# Cornering stiffnesses are per axle (N/rad), suspension values per corner.\n"
      << truth_table(run) << '\n';
  if (!out) throw InputError(path.string() + ": write failed");
}

void write_run(const std::filesystem::path& directory, const Run& run) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw InputError(directory.string() + ": cannot create: " + ec.message());
  write_channels_csv(directory / "channels.csv", run, false);
  write_channels_csv(directory / "channels_true.csv", run, true);
  write_truth(directory / "truth.toml", run);
  write_can_log(directory / "can.log", run);
}

}  // namespace dynid::sim
