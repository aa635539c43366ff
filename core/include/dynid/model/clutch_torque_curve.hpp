#pragma once
// ClutchTorqueCurveModel ("clutch_torque_curve"): the engine side of a slipping clutch on a car
// without a clamp-load sensor (production cars: a dual-clutch or automated gearbox carries its
// actuator's position on the bus, some manual cars their pedal's travel). The physics is
// clutch_slip's (clutch_slip.hpp):
//
//   T_e = J_e dw_e/dt + T_c,    T_c = C(e) sgn dw,    dw = w_e - w_in (slip speed),
//
// where C(e) = mu_c R F(e) is the clutch's Coulomb torque capacity as a function of its
// engagement e (channel clutch_engagement: 0 fully open, 1 fully closed; a pedal's travel maps
// to it with the signal's factor and offset). Without the clamp load F the friction
// coefficient mu_c cannot be separated from F(e): the curve C(e) is what the data give, and it is
// what a calibrator of an automated clutch wants (its touch point and slope).
//
// C(e) is piecewise linear: 0 up to touch_point, then linear between torque_curve_knots knots
// spaced evenly from touch_point to 1, and flat beyond the last. Its values at the knots are the
// parameters clutch_torque_1..n (N m), linear in the rows (hat functions), so the fit stays a
// least-squares fold. Why piecewise linear and not a polynomial: a diaphragm spring's load
// against travel has a knee, and a knot's value is local (a launch that never reaches full
// engagement leaves only the upper knots unexcited, which the parameter status then says).
// A clamp load linear in e between knots is recovered exactly (tests).
//
// One group "engine": y = engine_torque, columns [d_engine_speed, phi_1(e) sgn dw, ...,
// phi_n(e) sgn dw] for [engine_inertia, clutch_torque_1, ..., clutch_torque_n].
// Rows with e <= open_engagement (default: the touch point) carry no friction column: the clutch
// counts as open, and those rows (a standing car revving with the pedal down) give J_e and the
// torque offset alone.
// Rows left out, as in clutch_slip: |dw| < min_slip_speed (the clutch sticks; sgn undefined), and
// within stick_margin of such a sample; and an open row within stick_margin of a sample that is
// not open (the filter smears the engagement over its impulse response).
// open_engagement is clutch_slip's open_clamp_load on the travel: the clutch's first bite is a
// state change too. A launch's first rows, a few tens of newtons past the touch point, carry
// almost no friction but the filter's smear of the engine's change from idle to launch; with the
// touch point as the only threshold they took J_e +0.6 % on the bench car's noise-free launches
// (0.01 % with the threshold at clutch_slip's 150 N; docs/results/ACCURACY.md). Put it where the
// curve carries a few N m; rows below it lose that much friction, as with open_clamp_load.
//
// viscous_friction: the slip-proportional torque mu_v R F(e) dw, on the same basis: parameters
// clutch_viscous_1..n = mu_v R F(e_j) (N m s/rad), n columns phi_j(e) dw. A single mu_v / mu_c
// would multiply the unknown curve, a bilinear term; per knot it stays linear, and the ratio
// clutch_viscous_j / clutch_torque_j, mu_v / mu_c, is the same at every knot of a sound fit. It
// separates from the curve only where launches differ (the same engagement at different slips):
// launches alike make slip a function of engagement along one path.
// Not offered: Stribeck friction, whose speed enters nonlinearly (clutch_slip's bank).
//
// Constants (all optional): touch_point (-, 0: the engagement where the clutch starts to carry
// torque, in [0, 1)), open_engagement (-, the touch point; in [touch_point, 1)),
// torque_curve_knots (1..10, 4), min_slip_speed (rad/s, 1e-3), stick_margin (s, 0).
// Effects: viscous_friction, engine_torque_offset (ECU torque = true - T0, per run).
#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class ClutchTorqueCurveModel final : public RowModel {
 public:
  /// At most this many knots: more than a launch's slip can tell apart.
  static constexpr int kMaxKnots = 10;

  explicit ClutchTorqueCurveModel(const Constants& constants);

  std::string name() const override { return "clutch_torque_curve"; }
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"engine"}; }
  std::string group_unit(const std::string&) const override { return "N m"; }
  std::vector<std::string> measured_side() const override { return {"engine_torque"}; }
  /// At least stick_margin on both sides, and the default.
  RowReach reach(double sample_period) const override;
  std::vector<std::string> per_run_parameters() const override { return {"engine_torque_offset"}; }

  /// The knots' engagements, increasing, the last 1.
  const std::vector<double>& knots() const { return knots_; }
  /// The curve's basis at engagement e: phi_j(e) for j = 1..n (all 0 at or below the touch
  /// point; they sum to 1 at and above the first knot).
  std::vector<double> basis(double engagement) const;

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;

 private:
  bool open(double engagement) const { return engagement <= open_engagement_; }
  // Per sample: left out (near a sticking clutch, or open near a sample that is not).
  std::vector<bool> left_out(const ChannelSet& channels) const;

  double touch_point_ = 0.0;
  double open_engagement_ = 0.0;
  std::vector<double> knots_;
  double min_slip_;
  double stick_margin_ = 0.0;  // s
};

}  // namespace dynid::model
