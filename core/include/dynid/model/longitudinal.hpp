#pragma once
// LongitudinalModel: the vehicle's longitudinal force balance from CAN signals
// (nehaoua §6 and §10.4; venture §10 "longitudinal row"; borsotto §1.6 road load):
//
//   M dvx/dt = F_drive - 1/2 rho SCx vx|vx| - F_r sgn(vx)              (flat road, no braking)
//
//   F_drive = eta^s T_e G / r_w     source kEngineTorque: engine_torque T_e, gear_ratio G (engine
//                                   to wheel), s = +1 when T_e >= 0 and -1 when the engine
//                                   drags (power flows back through the driveline);
//                                   zero in neutral (gear 0, when `gear` is present);
//   F_drive = T_w / r_w             source kWheelTorque: wheel_torque T_w (driven wheels' sum).
//
// One group "longitudinal": y = F_drive, columns [d_vx, 1/2 rho vx|vx|, sgn vx] for the
// parameters [mass (kg), SCx (m^2), rolling_resistance F_r (N)]; the rolling-resistance
// coefficient is F_r / (M g). d_vx is the derivative of the wheel-speed-based vx, so on a slope
// the residual is M g sin(grade) (candidate effects road_grade, road_grade_accelerometer).
//
// Rows left out: |vx| < min_speed (sgn vx undefined, drag laws invalid at standstill); braking
// (brake_pressure > brake_pressure_threshold) unless brake_drag is enabled, since the brake
// force is not in the model; for the engine source, a slipping clutch (|engine_speed -
// gearbox_input_speed| > clutch_slip_tolerance, when both channels are present), since the
// engine torque then does not reach the wheels.
//
// Constants: wheel_radius (m), air_density (kg/m^3), driveline_efficiency (engine source,
// 0 < eta <= 1); optional gravity (9.80665), min_speed (1 m/s), brake_pressure_threshold
// (2e4 Pa), clutch_slip_tolerance (1 rad/s), clutch_slip_margin (s, 0: the rows within that
// long of a slipping sample are left out too, because the low-pass spreads a shift's transient
// over its impulse response; clutch_slip.hpp's stick_margin is the same for the clutch model),
// wheel_torque_zero (N m, 0: wheel source), brake_margin (s, 0: the rows within that long of a
// braking sample are left out too, for the same reason as clutch_slip_margin: the low-pass
// spreads the brake force's step into the rows before and after it, whose own filtered pressure
// is below the threshold; on the bench car's noise-free acceleration run one such row, 40 ms
// before the brakes, 19 N of brake force in it, took SCx -1.4 %; choose 2 / cut-off like the
// other margins).
//
// wheel_torque_zero: what the wheel-torque meter reads at zero torque, from the run's tare
// (ingest/zero_calibration.hpp: standing in neutral or with the clutch open, the driveshafts
// carry nothing); the model uses T_w = wheel_torque - wheel_torque_zero. Why not an offset
// column: within a run an offset T0 / r is a constant force, the same column as F_r sgn(vx)
// (the car never reverses), so no run separates it from rolling resistance; and across runs it
// differs (a strain-gauge zero drifts from run to run), so the coast-down (no torque: the
// homogeneous equation that scales SCx against the mass) and the acceleration run disagree on
// the constant, and least squares pays the mismatch in mass and SCx (reference simulator,
// 5 N m per run: -1.6 .. +0.8 % on the mass with the seed; -0.4 % on every seed with no
// offsets).
// The gear inferred (engine source, a car whose bus has no gear ratio: a manual gearbox, most
// production buses): with the constants gear_ratio_1 .. gear_ratio_<n> (the engine-to-wheel
// ratio in each forward gear, gearbox times final drive, at most kMaxGears, numbered without a
// hole) the model needs engine_speed instead of the gear_ratio channel. Each row's ratio is the
// listed one nearest to engine_speed r_w / vx (in log, i.e. relatively); a row where none is
// within gear_ratio_tolerance (relative, 0.03) is left out: the clutch slips or is open, or the
// car is in neutral or shifting, and the engine torque does not reach the wheels through a known
// ratio, and with it the rows within clutch_slip_margin of one, as for a measured slip. Why 3 %:
// the measured ratio differs from the gear's by the driven tyres' slip (about 1 % at 2 m/s^2) and
// their rolling radius against r_w (1-2 %), while a car's adjacent gears differ by 15 % or more (a
// list whose neighbours are within twice the tolerance is refused: a ratio between them would name
// either). A row whose clutch slips less than the tolerance keeps it: the torque it passes is the
// engine's less J_e d(engine_speed)/dt, not zero; but there the engine's acceleration is not G dvx
// / r_w, so rotating_inertia's column is off on those rows (the second car's launches:
// engine_inertia -1.2 % at 3 %, -0.15 % at 0.5 %, with its exact r_w; docs/results/ACCURACY.md). A
// profile whose rolling radius is measured can tighten it. Effects: road_grade,
// road_grade_accelerometer, linear_drag, brake_drag; engine source also engine_torque_offset and
// rotating_inertia (engine inertia seen through the gear: per-gear equivalent mass M + eta J_e G^2
// / r_w^2).
#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class LongitudinalModel final : public RowModel {
 public:
  enum class Source { kEngineTorque, kWheelTorque };
  /// Forward gears a profile may list (gear_ratio_1 .. gear_ratio_10).
  static constexpr int kMaxGears = 10;
  LongitudinalModel(const Constants& constants, Source source);

  std::string name() const override;
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"longitudinal"}; }
  std::string group_unit(const std::string&) const override { return "N"; }  // F_drive
  std::vector<std::string> measured_side() const override;

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;
  RowReach reach(double sample_period) const override;

 private:
  // The per-sample drive force and its factor F_drive / T (eta^s G / r_w or 1 / r_w).
  struct Drive {
    double force;
    double factor;
  };
  std::function<Drive(Eigen::Index)> drive(const ChannelSet& channels) const;
  // The engine-to-wheel ratio at each sample: the gear_ratio channel, or the listed gear's when
  // inferred (NaN where no gear fits: the row is left out).
  std::function<double(Eigen::Index)> ratio(const ChannelSet& channels) const;
  // Reads gear_ratio_1 .. gear_ratio_<kMaxGears> and gear_ratio_tolerance (header).
  void read_gear_ratios(const ConstantReader& c);

  Source source_;
  double wheel_radius_;
  double air_density_;
  double efficiency_ = 1.0;
  double gravity_;
  double min_speed_;
  double brake_threshold_;
  double slip_tolerance_;
  double slip_margin_ = 0.0;  // s
  double brake_margin_ = 0.0;  // s
  double wheel_torque_zero_ = 0.0;  // N m
  std::vector<double> gear_ratios_;  // ascending; empty: the gear_ratio channel is read
  double gear_ratio_tolerance_ = 0.03;
};

}  // namespace dynid::model
