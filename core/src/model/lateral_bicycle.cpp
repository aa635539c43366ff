#include "dynid/model/lateral_bicycle.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::excited;
using detail::parameter;
using detail::positive;

LateralBicycleModel::LateralBicycleModel(const Constants& constants) {
  const ConstantReader c(constants, name());
  a_ = c.positive("a", "m, CG to front axle");
  b_ = c.positive("b", "m, CG to rear axle");
  mass_ = c.optional("mass");
  if (mass_) mass_ = c.positive("mass", "kg, known vehicle mass");
  imu_x_ = c.optional("imu_x").value_or(0.0);
  min_speed_ = c.positive_or("min_speed", 1.0);
  gravity_ = c.positive_or("gravity", detail::kStandardGravity);
  brake_threshold_ = detail::brake_pressure_threshold(c);
  brake_margin_ = detail::optional_margin(c, "brake_margin");
}

ParameterInfo LateralBicycleModel::scaled(ParameterInfo p) const {
  return mass_ ? p : detail::per_unit_mass(std::move(p));
}

std::vector<ParameterInfo> LateralBicycleModel::parameters() const {
  // C_f, C_r > 0 in this sign convention: the slip angles d_f = steer - atan(..) and d_r are
  // those that give a positive (leftward) force, F_y = C d.
  return {
      scaled(excited(positive(parameter("yaw_inertia", "kg m^2", "yaw inertia at the CG")), 2500.0,
                     "d_yaw_rate (steer at several frequencies)")),
      scaled(excited(positive(parameter("front_cornering_stiffness", "N/rad", "front axle (both tyres)")),
                     1e5, "steer and ay (sine or step steer)")),
      scaled(excited(positive(parameter("rear_cornering_stiffness", "N/rad", "rear axle (both tyres)")),
                     1e5, "steer and ay (sine or step steer)"))};
}

std::vector<ChannelNeed> LateralBicycleModel::channels() const {
  return {{"vx", "m/s"},
          {"vy", "m/s"},
          {"ay", "m/s^2"},
          {"yaw_rate", "rad/s"},
          {"d_yaw_rate", "rad/s^2"},
          {"steer", "rad"},
          {"roll", "rad", true},
          {"az", "m/s^2", true},
          {"brake_pressure", "Pa", true}};
}

RowReach LateralBicycleModel::reach(double sample_period) const {
  return detail::widened(Model::reach(sample_period), brake_margin_, sample_period);
}

std::function<double(Eigen::Index)> LateralBicycleModel::road_plane_ay(const ChannelSet& set) const {
  const Eigen::VectorXd& ay = set["ay"];
  const Eigen::VectorXd* roll = detail::find(set, "roll");
  if (roll == nullptr) return [&ay](Eigen::Index k) { return ay(k); };
  // The body-fixed accelerometer turned back to the road plane: y_road = ay cos(roll) - az
  // sin(roll), with the measured az when present (it reads about +g), else gravity.
  const Eigen::VectorXd* az = detail::find(set, "az");
  const double g = gravity_;
  return [&ay, roll, az, g](Eigen::Index k) {
    const double vertical = az != nullptr ? (*az)(k) : g;
    return ay(k) * std::cos((*roll)(k)) - vertical * std::sin((*roll)(k));
  };
}

std::function<LateralBicycleModel::Slip(Eigen::Index)> LateralBicycleModel::slip(
    const ChannelSet& set) const {
  const Eigen::VectorXd& vx = set["vx"];
  const Eigen::VectorXd& vy = set["vy"];
  const Eigen::VectorXd& r = set["yaw_rate"];
  const Eigen::VectorXd& steer = set["steer"];
  return [&, a = a_, b = b_](Eigen::Index k) {
    return Slip{steer(k) - std::atan((vy(k) + a * r(k)) / vx(k)),
                -std::atan((vy(k) - b * r(k)) / vx(k)), std::cos(steer(k))};
  };
}

RowModel::EffectDefinition LateralBicycleModel::axle_effect(Effect info,
                                                            std::function<double(double)> law,
                                                            bool rear) const {
  EffectDefinition def{std::move(info), {}};
  def.bind = [this, law = std::move(law), rear](const ChannelSet& set) -> ColumnFn {
    return [s = slip(set), law, rear, a = a_, b = b_](Eigen::Index k, std::size_t g,
                                                      double* out) {
      const Slip v = s(k);
      const double front = law(v.front) * v.cos_steer;
      const double back = law(v.rear);
      out[0] = g == 0 ? front : -a * front;
      if (rear) out[1] = g == 0 ? back : b * back;
      return true;
    };
  };
  return def;
}

std::vector<RowModel::EffectDefinition> LateralBicycleModel::effect_definitions() const {
  return {axle_effect({effect::kSteerOffset, "steer sensor offset d0: a front force C_f d0",
                       {scaled(parameter("steer_offset_force", "N", "C_f times the offset", 0.0))},
                       {}},
                      [](double) { return 1.0; }, false),
          axle_effect({effect::kSlipOffset,
                       "constant slip-angle offsets e_f, e_r (steer, vy, yaw-rate offsets at a "
                       "steady speed): forces C_f e_f, C_r e_r",
                       {scaled(parameter("front_slip_offset_force", "N", "C_f e_f", 0.0)),
                        scaled(parameter("rear_slip_offset_force", "N", "C_r e_r", 0.0))},
                       {}},
                      [](double) { return 1.0; }, true),
          axle_effect({effect::kTyreSaturation,
                       "Fiala tyre before saturation: F_y = C d - C^2/(3 mu F_z) |d| d",
                       // -C^2/(3 mu F_z) <= 0: a tyre's force grows less than linearly with
                       // slip before it saturates, never more.
                       {scaled(detail::non_positive(
                            parameter("front_tyre_saturation", "N/rad^2", "|d| d coefficient"))),
                        scaled(detail::non_positive(
                            parameter("rear_tyre_saturation", "N/rad^2", "|d| d coefficient")))},
                       {}},
                      detail::signed_square, true),
          roll_acceleration()};
}

RowModel::EffectDefinition LateralBicycleModel::roll_acceleration() const {
  // No bounds: m_r h_r changes sign with the IMU above or below the roll axis, J_xz with the
  // tilt of the principal axes.
  EffectDefinition def{{effect::kRollAcceleration,
                        "roll acceleration of the body: lateral m_r h_r d2phi/dt2 (masses that do not roll "
                        "with the body, IMU above or below the rolling CG), yaw J_xz d2phi/dt2",
                        {scaled(parameter("roll_lateral_moment", "kg m", "lateral force per roll acceleration", 0.0)),
                         scaled(parameter("roll_yaw_product", "kg m^2", "yaw moment per roll acceleration", 0.0))},
                        {"roll_rate", "d_roll_rate"}},
                       {}};
  def.bind = [](const ChannelSet& set) -> ColumnFn {
    return [&droll = set["d_roll_rate"]](Eigen::Index k, std::size_t g, double* out) {
      out[g == 0 ? 0 : 1] = droll(k);
      return true;
    };
  };
  return def;
}

RowModel::RowFn LateralBicycleModel::bind(const ChannelSet& set,
                                          const std::vector<std::string>&) const {
  const Eigen::VectorXd& vx = set["vx"];
  const Eigen::VectorXd& dr = set["d_yaw_rate"];
  const double scale = mass_.value_or(1.0);
  // Braking rows and those within brake_margin of one (the header says why; the low-pass spreads
  // the brake force's step as in the longitudinal model).
  const std::vector<bool> braking =
      detail::near_braking(set, brake_threshold_, brake_margin_, false);
  return [=, this, &vx, &dr, ay = road_plane_ay(set), s = slip(set)](
             Eigen::Index k, std::size_t group, double* w, double& y) {
    if (vx(k) < min_speed_ || braking[static_cast<std::size_t>(k)]) return false;
    const Slip v = s(k);
    if (group == 0) {
      w[1] = v.front * v.cos_steer;
      w[2] = v.rear;
      y = scale * (ay(k) - imu_x_ * dr(k));
    } else {
      w[0] = dr(k);
      w[1] = -a_ * v.front * v.cos_steer;
      w[2] = b_ * v.rear;
      y = 0.0;
    }
    return true;
  };
}

}  // namespace dynid::model
