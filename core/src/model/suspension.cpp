#include "dynid/model/suspension.hpp"

#include <cmath>

#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::non_negative;
using detail::excited;
using detail::parameter;
using detail::positive;

SuspensionModel::SuspensionModel(const Constants& constants, const std::string& corner)
    : corner_(corner), opposite_(detail::opposite_corner(corner, "suspension_" + corner)) {
  min_speed_ = ConstantReader(constants, name()).positive_or("min_travel_speed", 1e-3);
}

std::vector<ParameterInfo> SuspensionModel::parameters() const {
  // Travel and force both positive in compression: k > 0, h >= 0 and f_s >= 0 (a damper and
  // a friction only dissipate); the offset -k z0 has either sign.
  const std::string travel = "susp_travel_" + corner_;
  return {excited(positive(parameter("stiffness", "N/m", "spring stiffness k")), 3e4,
                  travel + " (roll, pitch, heave)"),
          excited(non_negative(parameter("damping", "N s/m", "damper coefficient h")), 2000.0,
                  "d_" + travel + " (body motion)"),
          excited(non_negative(parameter("dry_friction", "N", "Coulomb friction f_s")), 100.0,
                  "d_" + travel + " changing sign (body motion)"),
          excited(parameter("force_offset", "N", "-k z0 (preload, travel sensor offset)"), std::nullopt,
                  "time: any run")};
}

std::vector<ChannelNeed> SuspensionModel::channels() const {
  return {{"susp_travel_" + corner_, "m"},
          {"d_susp_travel_" + corner_, "m/s"},
          {"susp_force_" + corner_, "N"},
          {"susp_travel_" + opposite_, "m", true}};
}

std::vector<RowModel::EffectDefinition> SuspensionModel::effect_definitions() const {
  const std::string travel = "susp_travel_" + corner_;
  const std::string other = "susp_travel_" + opposite_;
  const std::string speed = "d_susp_travel_" + corner_;
  return {detail::one_column(
              {effect::kAntiRollBar,
               "anti-roll bar k_ar (z - z_opposite)",
               {non_negative(parameter("anti_roll_bar_stiffness", "N/m", "k_ar, venture L864"))},
               {other}},
              [travel, other](const ChannelSet& set) -> detail::ValueFn {
                const Eigen::VectorXd& z = set[travel];
                const Eigen::VectorXd& zo = set[other];
                return [&z, &zo](Eigen::Index k) { return z(k) - zo(k); };
              }),
          detail::one_column({effect::kNonlinearDamping,
                              "quadratic damping |dz/dt| dz/dt",
                              // No bound: a digressive damper (blow-off valves) is h v with a
                              // negative |v| v term, and it is common.
                              {parameter("quadratic_damping", "N s^2/m^2", "")},
                              {}},
                             [speed](const ChannelSet& set) -> detail::ValueFn {
                               const Eigen::VectorXd& v = set[speed];
                               return [&v](Eigen::Index k) { return detail::signed_square(v(k)); };
                             }),
          detail::one_column({effect::kProgressiveStiffness,
                              "progressive spring (bump stop) z^3",
                              // No bound: a bump stop makes it positive, but a falling wheel
                              // rate (linkage geometry) is a negative one and is not impossible.
                              {parameter("cubic_stiffness", "N/m^3", "")},
                              {}},
                             [travel](const ChannelSet& set) -> detail::ValueFn {
                               const Eigen::VectorXd& z = set[travel];
                               return [&z](Eigen::Index k) { return z(k) * z(k) * z(k); };
                             })};
}

RowModel::RowFn SuspensionModel::bind(const ChannelSet& set,
                                      const std::vector<std::string>&) const {
  const Eigen::VectorXd& z = set["susp_travel_" + corner_];
  const Eigen::VectorXd& v = set["d_susp_travel_" + corner_];
  const Eigen::VectorXd& f = set["susp_force_" + corner_];
  return [&z, &v, &f, min = min_speed_](Eigen::Index k, std::size_t, double* w, double& y) {
    if (std::abs(v(k)) < min) return false;
    w[0] = z(k);
    w[1] = v(k);
    w[2] = detail::sgn(v(k));
    w[3] = 1.0;
    y = f(k);
    return true;
  };
}

}  // namespace dynid::model
