#pragma once
// SuspensionModel: the force through one suspension corner (venture §3.5, L817 and L864;
// decoupled suspension sub-system of §2.7-2.8):
//
//   F_i = k (z_i - z0) + h dz_i/dt + f_s sgn(dz_i/dt)   [+ k_ar (z_i - z_opposite)]
//
// z = susp_travel_<c> (m, positive in compression), F = susp_force_<c> (N). One group
// "suspension": y = F, columns [z, dz/dt, sgn dz/dt, 1] for [stiffness (N/m), damping
// (N s/m), dry_friction (N), force_offset = -k z0 (N)].
// Rows left out: |dz/dt| < min_travel_speed (stiction: the dry-friction force is anywhere in
// [-f_s, f_s] there, the Karnopp dead band of borsotto §2.1).
//
// Constants: optional min_travel_speed (m/s, 1e-3). Effects: anti_roll_bar (coupling to the
// opposite corner of the axle, k_ar in N/m; venture §7 item 1: without it the stiffness absorbs
// the bar), nonlinear_damping (|dz/dt| dz/dt, venture §7 item 11), progressive_stiffness (z^3,
// bump stops).
#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class SuspensionModel final : public RowModel {
 public:
  /// `corner` is fl, fr, rl or rr (InputError otherwise).
  SuspensionModel(const Constants& constants, const std::string& corner);

  std::string name() const override { return "suspension_" + corner_; }
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"suspension"}; }
  std::string group_unit(const std::string&) const override { return "N"; }
  std::vector<std::string> measured_side() const override { return {"susp_force_" + corner_}; }

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;

 private:
  std::string corner_;
  std::string opposite_;
  double min_speed_;
};

}  // namespace dynid::model
