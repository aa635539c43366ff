#include "dynid/model/tyre_vertical.hpp"

#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::non_negative;
using detail::excited;
using detail::parameter;
using detail::positive;

TyreVerticalModel::TyreVerticalModel(const Constants&, const std::string& corner)
    : corner_(corner) {
  detail::opposite_corner(corner, "tyre_" + corner);  // validates the corner
}

std::vector<ParameterInfo> TyreVerticalModel::parameters() const {
  return {excited(positive(parameter("vertical_stiffness", "N/m", "tyre vertical stiffness k_p")), 2.5e5,
                  "tyre_deflection_" + corner_ + " (load transfer: steer, brake, bumps)"),
          excited(parameter("force_offset", "N", "load at zero measured deflection (sensor offsets)"),
                  std::nullopt, "time: any run")};
}

std::vector<ChannelNeed> TyreVerticalModel::channels() const {
  return {{"tyre_deflection_" + corner_, "m"},
          {"tyre_force_z_" + corner_, "N"},
          {"d_tyre_deflection_" + corner_, "m/s", true}};
}

std::vector<RowModel::EffectDefinition> TyreVerticalModel::effect_definitions() const {
  const std::string deflection = "tyre_deflection_" + corner_;
  const std::string speed = "d_tyre_deflection_" + corner_;
  return {
      detail::one_column({effect::kTyreDamping,
                          "tyre damping c_p dz_p/dt",
                          {non_negative(parameter("tyre_damping", "N s/m", ""))},
                          {speed}},
                         [speed](const ChannelSet& set) { return detail::channel(set, speed); }),
      detail::one_column({effect::kProgressiveStiffness,
                          "progressive tyre stiffness z_p^2",
                          // No bound: a tyre's load-deflection curve is mildly
                          // progressive or degressive with pressure and construction.
                          {parameter("quadratic_stiffness", "N/m^2", "")},
                          {}},
                         [deflection](const ChannelSet& set) -> detail::ValueFn {
                           const Eigen::VectorXd& z = set[deflection];
                           return [&z](Eigen::Index k) { return z(k) * z(k); };
                         })};
}

RowModel::RowFn TyreVerticalModel::bind(const ChannelSet& set,
                                        const std::vector<std::string>&) const {
  const Eigen::VectorXd& z = set["tyre_deflection_" + corner_];
  const Eigen::VectorXd& f = set["tyre_force_z_" + corner_];
  return [&z, &f](Eigen::Index k, std::size_t, double* w, double& y) {
    if (z(k) <= 0.0) return false;
    w[0] = z(k);
    w[1] = 1.0;
    y = f(k);
    return true;
  };
}

}  // namespace dynid::model
