#include "dynid/model/clutch_slip.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::excited;
using detail::parameter;
using detail::positive;

ClutchSlipModel::ClutchSlipModel(const Constants& constants) {
  const ConstantReader c(constants, name());
  radius_ = c.positive("clutch_friction_radius", "m, R_eq times the number of friction faces");
  if (c.optional("stribeck_speed"))
    stribeck_speed_ = c.positive("stribeck_speed", "rad/s, Stribeck speed v_s");
  min_slip_ = c.positive_or("min_slip_speed", 1e-3);
  clamp_load_zero_ = c.optional("clutch_clamp_load_zero").value_or(0.0);
  open_clamp_load_ = c.optional("open_clamp_load").value_or(0.0);
  stick_margin_ = detail::optional_margin(c, "stick_margin");
}

Eigen::Index ClutchSlipModel::margin_samples(double sample_period) const {
  return detail::margin_samples(stick_margin_, sample_period);
}

RowReach ClutchSlipModel::reach(double sample_period) const {
  return detail::widened(RowReach{}, stick_margin_, sample_period);
}

std::vector<bool> ClutchSlipModel::near_stick(const ChannelSet& set) const {
  const Eigen::Index margin = margin_samples(set.sample_period());
  std::vector<bool> out =
      detail::within_margin_of(set.samples(), margin, detail::clutch_sticks(set, min_slip_));
  if (open_clamp_load_ <= 0.0) return out;
  // The other state change: a row counted open (Gamma_n = 0) within the margin of a sample
  // that is not (the clutch closes or opens there).
  const Eigen::VectorXd& load = set["clutch_clamp_load"];
  const auto gamma = clamp_load();
  const std::vector<bool> near_closed =
      detail::within_margin_of(set.samples(), margin, [&](Eigen::Index k) { return gamma(load(k)) > 0.0; });
  for (Eigen::Index k = 0; k < set.samples(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (near_closed[i] && gamma(load(k)) == 0.0) out[i] = true;
  }
  return out;
}

std::function<double(double)> ClutchSlipModel::clamp_load() const {
  return [zero = clamp_load_zero_, open = open_clamp_load_](double measured) {
    const double load = measured - zero;
    return load < open ? 0.0 : load;
  };
}

std::vector<ParameterInfo> ClutchSlipModel::parameters() const {
  return {excited(detail::measures(positive(parameter("engine_inertia", "kg m^2",
                                                      "engine and flywheel inertia J_e")),
                                   "engine_inertia"),
                  0.2, "d_engine_speed while the clutch slips (launches)"),
          excited(detail::bounded(
                      parameter("coulomb_friction", "-", "Coulomb friction coefficient mu_c"), 0.0,
                      2.0),
                  0.3, "clutch_clamp_load while the clutch slips (launches)")};
}

std::vector<ChannelNeed> ClutchSlipModel::channels() const {
  return {{"engine_speed", "rad/s"},
          {"d_engine_speed", "rad/s^2"},
          {"engine_torque", "N m"},
          {"gearbox_input_speed", "rad/s"},
          {"clutch_clamp_load", "N"}};
}

RowModel::EffectDefinition ClutchSlipModel::friction_effect(Effect info,
                                                            std::function<double(double)> law) const {
  return detail::one_column(
      std::move(info), [law = std::move(law), radius = radius_, gamma = clamp_load()](const ChannelSet& set) {
        const Eigen::VectorXd& we = set["engine_speed"];
        const Eigen::VectorXd& wi = set["gearbox_input_speed"];
        const Eigen::VectorXd& load = set["clutch_clamp_load"];
        return detail::ValueFn([&we, &wi, &load, law, radius, gamma](Eigen::Index k) {
          return gamma(load(k)) * radius * law(we(k) - wi(k));
        });
      });
}

std::vector<RowModel::EffectDefinition> ClutchSlipModel::effect_definitions() const {
  std::vector<EffectDefinition> out{
      friction_effect({effect::kViscous,
                       "viscous friction Gamma_n mu_v dw",
                       // No bound: a facing's mu may fall with slip speed (the cause of
                       // judder), a negative mu_v over the slips of a launch.
                       {parameter("viscous_friction", "s/rad", "mu_v")},
                       {}},
                      [](double slip) { return slip; }),
      detail::clutch_torque_offset()};
  if (!stribeck_speed_) return out;
  const double vs = *stribeck_speed_;
  out.push_back(friction_effect(
      {effect::kStribeck,
       "Stribeck friction Gamma_n (mu_s - mu_c) exp(-(dw/v_s)^2) sgn dw, v_s = " +
           std::to_string(vs) + " rad/s",
       // No bound: mu_s > mu_c for most pairs, but clutch facings are made with mu rising
       // with slip (anti-judder), mu_s - mu_c < 0.
       {parameter("stribeck_friction", "-", "mu_s - mu_c")},
       {}},
      [vs](double slip) { return std::exp(-(slip / vs) * (slip / vs)) * detail::sgn(slip); }));
  return out;
}

RowModel::RowFn ClutchSlipModel::bind(const ChannelSet& set,
                                      const std::vector<std::string>&) const {
  const Eigen::VectorXd& we = set["engine_speed"];
  const Eigen::VectorXd& dwe = set["d_engine_speed"];
  const Eigen::VectorXd& te = set["engine_torque"];
  const Eigen::VectorXd& wi = set["gearbox_input_speed"];
  const Eigen::VectorXd& load = set["clutch_clamp_load"];
  return [&, radius = radius_, gamma = clamp_load(), stuck = near_stick(set)](Eigen::Index k, std::size_t,
                                                                                double* w, double& y) {
    const double slip = we(k) - wi(k);
    if (stuck[static_cast<std::size_t>(k)]) return false;
    w[0] = dwe(k);
    w[1] = gamma(load(k)) * radius * detail::sgn(slip);
    y = te(k);
    return true;
  };
}

}  // namespace dynid::model
