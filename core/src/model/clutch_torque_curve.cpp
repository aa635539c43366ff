#include "dynid/model/clutch_torque_curve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::excited;
using detail::parameter;

namespace {

std::string engagement_text(double e) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", e);
  return buf;
}

}  // namespace

ClutchTorqueCurveModel::ClutchTorqueCurveModel(const Constants& constants) {
  const ConstantReader c(constants, name());
  touch_point_ = c.optional("touch_point").value_or(0.0);
  if (touch_point_ < 0.0 || touch_point_ >= 1.0)
    throw InputError(
        "model '" + name() + "': constant 'touch_point' = " + std::to_string(touch_point_) +
        " must be in [0, 1) (the clutch_engagement where the clutch starts to carry torque)");
  open_engagement_ = c.optional("open_engagement").value_or(touch_point_);
  if (open_engagement_ < touch_point_ || open_engagement_ >= 1.0)
    throw InputError("model '" + name() +
                     "': constant 'open_engagement' = " + std::to_string(open_engagement_) +
                     " must be in [touch_point, 1) (below it the clutch counts as open)");
  const double knots = c.positive_or("torque_curve_knots", 4.0);
  if (knots != std::floor(knots) || knots > kMaxKnots)
    throw InputError("model '" + name() +
                     "': constant 'torque_curve_knots' = " + std::to_string(knots) +
                     " must be a whole number from 1 to " + std::to_string(kMaxKnots));
  const int n = static_cast<int>(knots);
  for (int j = 1; j <= n; ++j) knots_.push_back(touch_point_ + (1.0 - touch_point_) * j / n);
  knots_.back() = 1.0;
  min_slip_ = c.positive_or("min_slip_speed", 1e-3);
  stick_margin_ = detail::optional_margin(c, "stick_margin");
}

std::vector<double> ClutchTorqueCurveModel::basis(double e) const {
  // A NaN travel gives NaN columns, which RowModel refuses naming the sample (no knot to index).
  if (std::isnan(e))
    return std::vector<double>(knots_.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<double> phi(knots_.size(), 0.0);
  if (open(e)) return phi;
  if (e >= knots_.back()) {
    phi.back() = 1.0;
    return phi;
  }
  // The segment [lower, knots_[j]] holding e; below the first knot, lower is the touch point,
  // whose value (0) is not a parameter.
  const auto j =
      static_cast<std::size_t>(std::upper_bound(knots_.begin(), knots_.end(), e) - knots_.begin());
  const double lower = j == 0 ? touch_point_ : knots_[j - 1];
  const double t = (e - lower) / (knots_[j] - lower);
  phi[j] = t;
  if (j > 0) phi[j - 1] = 1.0 - t;
  return phi;
}

RowReach ClutchTorqueCurveModel::reach(double sample_period) const {
  return detail::widened(RowReach{}, stick_margin_, sample_period);
}

std::vector<bool> ClutchTorqueCurveModel::left_out(const ChannelSet& set) const {
  const Eigen::Index margin = detail::margin_samples(stick_margin_, set.sample_period());
  std::vector<bool> out =
      detail::within_margin_of(set.samples(), margin, detail::clutch_sticks(set, min_slip_));
  const Eigen::VectorXd& e = set["clutch_engagement"];
  const std::vector<bool> near_closed =
      detail::within_margin_of(set.samples(), margin, [&](Eigen::Index k) { return !open(e(k)); });
  for (Eigen::Index k = 0; k < set.samples(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (near_closed[i] && open(e(k))) out[i] = true;
  }
  return out;
}

std::vector<ParameterInfo> ClutchTorqueCurveModel::parameters() const {
  std::vector<ParameterInfo> out{
      excited(detail::measures(detail::positive(parameter("engine_inertia", "kg m^2",
                                                          "engine and flywheel inertia J_e")),
                               "engine_inertia"),
              0.2, "d_engine_speed while the clutch slips (launches)")};
  for (std::size_t j = 0; j < knots_.size(); ++j) {
    const std::string at = engagement_text(knots_[j]);
    out.push_back(excited(
        detail::non_negative(parameter("clutch_torque_" + std::to_string(j + 1), "N m",
                                       "Coulomb torque capacity at clutch_engagement " + at)),
        std::nullopt, "slip with clutch_engagement near " + at + " (launches)"));
  }
  return out;
}

std::vector<ChannelNeed> ClutchTorqueCurveModel::channels() const {
  return {{"engine_speed", "rad/s"},
          {"d_engine_speed", "rad/s^2"},
          {"engine_torque", "N m"},
          {"gearbox_input_speed", "rad/s"},
          {"clutch_engagement", "-"}};
}

std::vector<RowModel::EffectDefinition> ClutchTorqueCurveModel::effect_definitions() const {
  // viscous_friction: mu_v R F(e) dw, with F(e) on the curve's basis, is sum_j v_j phi_j(e) dw with
  // v_j = mu_v R F(e_j): one column per knot, linear (a single mu_v / mu_c would be bilinear).
  // No bound: a facing's mu may fall with slip speed (clutch_slip's viscous_friction).
  Effect viscous{effect::kViscous, "viscous friction mu_v R F(e) dw, one value per knot", {}, {}};
  for (std::size_t j = 0; j < knots_.size(); ++j)
    viscous.parameters.push_back(
        parameter("clutch_viscous_" + std::to_string(j + 1), "N m s/rad",
                  "slip-proportional torque at clutch_engagement " + engagement_text(knots_[j])));
  EffectDefinition curve{std::move(viscous), [this](const ChannelSet& set) -> ColumnFn {
                           return [this, &we = set["engine_speed"],
                                   &wi = set["gearbox_input_speed"], &e = set["clutch_engagement"]](
                                      Eigen::Index k, std::size_t, double* out) {
                             const double slip = we(k) - wi(k);
                             const std::vector<double> phi = basis(e(k));
                             for (std::size_t j = 0; j < phi.size(); ++j) out[j] = phi[j] * slip;
                             return true;
                           };
                         }};
  return {std::move(curve), detail::clutch_torque_offset()};
}

RowModel::RowFn ClutchTorqueCurveModel::bind(const ChannelSet& set,
                                             const std::vector<std::string>&) const {
  const Eigen::VectorXd& we = set["engine_speed"];
  const Eigen::VectorXd& dwe = set["d_engine_speed"];
  const Eigen::VectorXd& te = set["engine_torque"];
  const Eigen::VectorXd& wi = set["gearbox_input_speed"];
  const Eigen::VectorXd& e = set["clutch_engagement"];
  return [&, this, skip = left_out(set)](Eigen::Index k, std::size_t, double* w, double& y) {
    if (skip[static_cast<std::size_t>(k)]) return false;
    w[0] = dwe(k);
    const double sign = detail::sgn(we(k) - wi(k));
    const std::vector<double> phi = basis(e(k));
    for (std::size_t j = 0; j < phi.size(); ++j) w[j + 1] = phi[j] * sign;
    y = te(k);
    return true;
  };
}

}  // namespace dynid::model
