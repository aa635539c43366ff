#pragma once
// LockedDrivelineModel: the driveline with the clutch locked, one model per gear (borsotto
// §1.2-1.3 rigid model eq. 4.14 and road load 4.15c, §1.6, §8.2 row V3; §5 item 14: every
// reduced parameter scales with the gear ratio, so identify per gear):
//
//   T_e = J_eq dw/dt + p + q w + r w^2        (w = engine_speed = gearbox input when locked)
//
// J_eq = J_e + J_bv (engine plus the vehicle reduced to the engine shaft). One group
// "driveline": y = engine_torque, columns [d_engine_speed, 1, w, w^2] for [equivalent_inertia
// (kg m^2), road_load_constant p (N m), road_load_linear q (N m s/rad), road_load_quadratic r
// (N m s^2/rad^2)] (p: rolling resistance, q w + r w^2: aerodynamic drag, borsotto L3502).
// Rows left out: another gear; a sample next to a gear change (the derivative spans the shift);
// clutch slipping (|engine_speed - gearbox_input_speed| > lock_slip_tolerance, when present);
// braking (brake_pressure > brake_pressure_threshold) unless brake_drag is enabled.
//
// Constants: gear (the engaged gear this model is for, an integer >= 1); optional
// lock_slip_tolerance (rad/s, 1), brake_pressure_threshold (Pa, 2e4).
// Effects: road_grade (sin(grade) with the grade torque M g r_w / alpha, borsotto L3720),
// brake_drag (N m/Pa).
#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class LockedDrivelineModel final : public RowModel {
 public:
  explicit LockedDrivelineModel(const Constants& constants);

  std::string name() const override { return "locked_driveline_gear" + std::to_string(gear_); }
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"driveline"}; }
  std::string group_unit(const std::string&) const override { return "N m"; }
  std::vector<std::string> measured_side() const override { return {"engine_torque"}; }
  long gear() const { return gear_; }

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;

 private:
  long gear_;
  double slip_tolerance_;
  double brake_threshold_;
};

}  // namespace dynid::model
