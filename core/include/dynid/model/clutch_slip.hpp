#pragma once
// ClutchSlipModel: the engine side of a slipping clutch (borsotto §1.3 eq. 4.15-4.16, §2.5
// final mu model, §8.2 row V1):
//
//   T_e = J_e dw_e/dt + T_c,    T_c = Gamma_n mu(dw),   dw = w_e - w_in (slip speed),
//   mu(dw) = mu_c sgn dw + (mu_s - mu_c) exp(-(dw/v_s)^2) sgn dw + mu_v dw   (Stribeck, d_s = 2)
//
// Gamma_n = clutch_clamp_load * clutch_friction_radius (the equivalent radius R_eq of
// borsotto §2.5 times the number of friction faces). One group "engine": y = engine_torque,
// columns [d_engine_speed, Gamma_n sgn dw] for [engine_inertia (kg m^2), coulomb_friction mu_c
// (-)]; the effects viscous_friction (Gamma_n dw, mu_v in s/rad) and stribeck_friction
// (Gamma_n exp(-(dw/v_s)^2) sgn dw, mu_s - mu_c) complete borsotto's Stribeck model. v_s enters
// nonlinearly: it is a constant of the model, chosen by StribeckSpeedBank (stribeck_bank.hpp)
// among candidates by minimum residual (borsotto §8.4).
// Rows left out: |dw| < min_slip_speed (sgn undefined: the clutch sticks; borsotto's dv), and
// every row within stick_margin seconds of such a sample (borsotto §8.4: drop rows near clutch
// state changes). Why: the channels are low-passed forward-backward before the rows are built,
// so a row a few samples from a lock-up carries the stuck clutch's torque and the kink of the
// engine speed through the filter window, while its own (filtered) slip still looks large. On
// the reference simulator those rows took mu_c from 0.159 to 0.093 (min_slip_speed = 3 rad/s,
// 5 Hz filter); with a margin of about 2 / cut-off they are gone. A larger min_slip_speed does
// the same only by luck of the slip rate near lock.
// The mask reads stick_margin on both sides of a row: reach() says so, so that a streaming
// caller keeps that much context and look-ahead (with the default 3/1 samples of
// ingest::RunProcessor the rule saw only stuck samples inside the current window: the rows of
// a clutch release at the rev limit, filtered load still 1..9 kN, came in or not with the
// chunking; mu_c -6..-23 % on launch runs longer than 40 s).
//
// Constants: clutch_friction_radius (m); optional stribeck_speed (rad/s; without it the
// stribeck_friction effect is not offered), min_slip_speed (rad/s, 1e-3), stick_margin (s, 0),
// clutch_clamp_load_zero (N, 0), open_clamp_load (N, 0).
//
// clutch_clamp_load_zero: what the clamp-load sensor reads with the clutch fully open (zero
// load), from the run's tare (ingest/zero_calibration.hpp); every friction column uses
// Gamma_n = (clutch_clamp_load - clutch_clamp_load_zero) R. Why not an offset column: the offset
// F0 multiplies every friction term (R F0 mu(dw)), so it would take one bilinear column per term;
// its Coulomb part is a constant torque on a launch (slip always > 0), the same column as
// engine_torque_offset; and its viscous part R F0 mu_v dw is a column the model does not have,
// weighing most where the load is small (engagement starts from 0, and the clutch-open rows of
// a standing start carry F0 alone). The engaging slip of a launch happens at small loads (the
// clutch locks at ~3-4 kN of 12 kN on the reference simulator), so mu_c moves by ~0.3 % per N
// of zero error: a 1 s tare (~5 N) is not enough, 5 s (~2 N) is.
//
// open_clamp_load: below it (after the zero) the clutch counts as open, Gamma_n = 0: the rows
// of a standing or stopping car (clutch pedal down, large slip) keep J_e and the torque offset
// and carry no friction column. Why: there the measured load is the sensor's noise and residual
// zero error, which the friction columns multiply by mu(dw) at slips up to ~250 rad/s (viscous
// term), spoiling J_e and mu_c. The price: the true friction torque below the threshold,
// mu(dw) R open_clamp_load, is missing from those rows: < 3 N m at small slip, but up to ~18 N m
// in a launch's first ~40 ms at 250 rad/s (mu_v dw ~ 0.9). Choose ~5 sigma of the load sensor's
// noise. The load crossing open_clamp_load is a clutch state change like a lock-up: with a
// stick_margin, an open row within the margin of a sample that is not open is left out too (the
// launch's first rows, whose true friction the zeroed column cannot explain, and the filter's
// smear of the engagement and of the release). Why: on the bench car's noise-free launch run those
// rows, one decimated row per launch with 2..10 N m of friction, took J_e -0.32 % and mu_c
// +0.07 % (bench/coverage, docs/ACCURACY.md); the margin (2 / cut-off) is longer than a launch's
// load takes to cross the threshold (~0.07 s), so none is left. Without a margin nothing changes.
// Effects: viscous_friction, stribeck_friction, engine_torque_offset (ECU torque = true - T0).
#include <optional>

#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class ClutchSlipModel final : public RowModel {
 public:
  explicit ClutchSlipModel(const Constants& constants);

  std::string name() const override { return "clutch_slip"; }
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"engine"}; }
  std::string group_unit(const std::string&) const override { return "N m"; }
  std::vector<std::string> measured_side() const override { return {"engine_torque"}; }
  std::optional<double> stribeck_speed() const { return stribeck_speed_; }
  /// At least stick_margin on both sides (near_stick), and the default.
  RowReach reach(double sample_period) const override;
  /// engine_torque_offset: the ECU's torque offset differs from run to run.
  std::vector<std::string> per_run_parameters() const override { return {"engine_torque_offset"}; }

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;

 private:
  // A column Gamma_n * law(slip).
  EffectDefinition friction_effect(Effect info, std::function<double(double)> law) const;

  // The clamp load the friction columns use, from the measured one: the tare's zero removed,
  // and 0 below open_clamp_load.
  std::function<double(double)> clamp_load() const;

  // Samples of stick_margin at this sample period.
  Eigen::Index margin_samples(double sample_period) const;
  // Per sample: within stick_margin of a sample whose |slip| < min_slip_speed.
  std::vector<bool> near_stick(const ChannelSet& channels) const;

  double radius_;
  std::optional<double> stribeck_speed_;
  double min_slip_;
  double stick_margin_ = 0.0;  // s
  double clamp_load_zero_ = 0.0;  // N
  double open_clamp_load_ = 0.0;  // N
};

}  // namespace dynid::model
