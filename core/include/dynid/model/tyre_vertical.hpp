#pragma once
// TyreVerticalModel: vertical stiffness of one tyre (venture §3.1, F_p = k_p z_p, L530; the
// decoupled tyre sub-system of §2.7-2.8, with an offset as in venture §7 item 14):
//
//   F_z = k_p z_p + F_0
//
// z_p = tyre_deflection_<c> (m), F_z = tyre_force_z_<c> (N). One group "tyre": columns
// [z_p, 1] for [vertical_stiffness (N/m), force_offset (N)]. Rows left out: z_p <= 0 (wheel off
// the ground: the spring law does not hold). No constants.
// Effects: tyre_damping (d_tyre_deflection_<c>, N s/m; venture neglects it, L513),
// progressive_stiffness (z_p^2, N/m^2).
#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class TyreVerticalModel final : public RowModel {
 public:
  /// `corner` is fl, fr, rl or rr (InputError otherwise).
  TyreVerticalModel(const Constants& constants, const std::string& corner);

  std::string name() const override { return "tyre_" + corner_; }
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"tyre"}; }
  std::string group_unit(const std::string&) const override { return "N"; }
  std::vector<std::string> measured_side() const override { return {"tyre_force_z_" + corner_}; }

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;

 private:
  std::string corner_;
};

}  // namespace dynid::model
