#pragma once
// LateralNoVyModel ("lateral_bicycle_no_vy"): the single-track model of lateral_bicycle.hpp for
// a production car, whose bus has steer, yaw rate, ay and vx but no sideslip sensor (vy needs an
// optical sensor). Integrating ay - vx r for vy drifts with the accelerometer's offset and
// noise, so the sideslip is eliminated instead, exactly, from the model's own equations.
//
// The linear bicycle (small slip angles, cos(steer) = 1; at 0.05 rad of slip atan is 0.08 % off):
//
//   d_f = steer - (vy + a r) / vx,   d_r = -(vy - b r) / vx,   F_yf = C_f d_f,   F_yr = C_r d_r
//   M ay = F_yf + F_yr                J dr/dt = a F_yf - b F_yr                 ay = dvy/dt + vx r
//
// With beta = vy / vx and rho = r / vx the lateral equation gives
// (C_f + C_r) beta = C_f steer - (a C_f - b C_r) rho - M ay, linear in (C_f, C_r, M), so:
//
// Group "sideslip" (the lateral equation differentiated, d beta/dt = (ay - vx r - dvx/dt beta)
// / vx put in):
//   C_f X_f + C_r X_r = -M (d_ay + (dvx/dt / vx) ay)
//   X_f = ay / vx - r - (dvx/dt / vx)(steer - a rho) - d_steer + a d_rho
//   X_r = ay / vx - r - (dvx/dt / vx) b rho - b d_rho,      d_rho = d_yaw_rate / vx - r dvx/dt /
//   vx^2
// Group "yaw" (beta eliminated between the two equations, divided by C_f C_r L, L = a + b):
//   steer - L rho = T d_yaw_rate + K ay
//   T = J (C_f + C_r) / (L C_f C_r)   (s^2: the steer the yaw acceleration takes)
//   K = M (b C_r - a C_f) / (L C_f C_r)   (the understeer gradient, rad per m/s^2)
//
// Parameters [front_cornering_stiffness, rear_cornering_stiffness, steer_per_yaw_acceleration,
// understeer_gradient]; without the optional constant `mass` the stiffnesses are per unit mass
// (the sideslip equation is homogeneous in M, C_f, C_r) and T and K, ratios, are the same. The
// yaw inertia follows from them: J / M = T L c_f c_r / (c_f + c_r) (c = C / M); K is implied by
// c_f, c_r as well (K = (b / c_f - a / c_r) / L), and is identified on its own so that the yaw
// equation stays linear: the two values of K are a check of the model, not a constraint.
// The sideslip equation reads the derivatives of ay and steer: its regressors are small
// differences of noisy signals, so the stiffnesses are less certain than with vy (on the second
// car's swept sine: 0.9-1.0 % std against 0.2 %; T 0.3 %, K 0.7 %; docs/results/ACCURACY.md),
// and least squares is attenuated by the regressors' noise (`dynid iv`, `dynid simex`).
//
// ay is taken at the CG (no imu_x: its correction would need the yaw rate's second derivative).
// Rows left out, as lateral_bicycle's: vx < min_speed, braking (brake_pressure above
// brake_pressure_threshold, within brake_margin of it). Constants: a, b (m); optional mass (kg),
// min_speed (m/s, 1), brake_pressure_threshold (Pa, 2e4), brake_margin (s, 0).
#include <optional>

#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class LateralNoVyModel final : public RowModel {
 public:
  explicit LateralNoVyModel(const Constants& constants);

  std::string name() const override { return "lateral_bicycle_no_vy"; }
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"sideslip", "yaw"}; }
  /// The sideslip row is a force rate (N/s; per unit mass m/s^3), the yaw row a steer angle.
  std::string group_unit(const std::string& group) const override {
    if (group == "sideslip") return mass_ ? "N/s" : "m/s^3";
    return "rad";
  }
  std::vector<std::string> measured_side() const override { return {"ay", "d_ay"}; }

 protected:
  std::vector<EffectDefinition> effect_definitions() const override { return {}; }
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;
  RowReach reach(double sample_period) const override;

 private:
  // The parameter as identified: per unit mass when the mass is not known.
  ParameterInfo scaled(ParameterInfo p) const;

  double a_;
  double b_;
  std::optional<double> mass_;
  double min_speed_;
  double brake_threshold_;
  double brake_margin_;
};

}  // namespace dynid::model
