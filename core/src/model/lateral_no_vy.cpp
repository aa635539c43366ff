#include "dynid/model/lateral_no_vy.hpp"

#include <algorithm>
#include <utility>

#include "support.hpp"

namespace dynid::model {

using detail::excited;
using detail::parameter;
using detail::positive;

LateralNoVyModel::LateralNoVyModel(const Constants& constants) {
  const ConstantReader c(constants, name());
  a_ = c.positive("a", "m, CG to front axle");
  b_ = c.positive("b", "m, CG to rear axle");
  mass_ = c.optional("mass");
  if (mass_) mass_ = c.positive("mass", "kg, known vehicle mass");
  min_speed_ = c.positive_or("min_speed", 1.0);
  brake_threshold_ = detail::brake_pressure_threshold(c);
  brake_margin_ = detail::optional_margin(c, "brake_margin");
}

ParameterInfo LateralNoVyModel::scaled(ParameterInfo p) const {
  return mass_ ? p : detail::per_unit_mass(std::move(p));
}

std::vector<ParameterInfo> LateralNoVyModel::parameters() const {
  // The stiffnesses are seen through the sideslip's rate only: steer at several frequencies.
  // T > 0 (J, C > 0); K takes either sign (understeer > 0, oversteer < 0).
  return {
      scaled(excited(
          positive(parameter("front_cornering_stiffness", "N/rad", "front axle (both tyres)")), 1e5,
          "steer at several frequencies (sine sweep)")),
      scaled(excited(
          positive(parameter("rear_cornering_stiffness", "N/rad", "rear axle (both tyres)")), 1e5,
          "steer at several frequencies (sine sweep)")),
      excited(
          positive(parameter("steer_per_yaw_acceleration", "s^2",
                             "J (C_f + C_r) / (L C_f C_r): the steer the yaw acceleration takes")),
          0.02, "d_yaw_rate (steer at several frequencies)"),
      excited(parameter("understeer_gradient", "rad/(m/s^2)",
                        "M (b C_r - a C_f) / (L C_f C_r): steer beyond L r / vx per m/s^2 of ay"),
              0.004, "ay (steady cornering or slow sine steer)")};
}

std::vector<ChannelNeed> LateralNoVyModel::channels() const {
  return {{"vx", "m/s"},       {"d_vx", "m/s^2"},     {"ay", "m/s^2"},
          {"d_ay", "m/s^2/s"}, {"yaw_rate", "rad/s"}, {"d_yaw_rate", "rad/s^2"},
          {"steer", "rad"},    {"d_steer", "rad/s"},  {"brake_pressure", "Pa", true}};
}

RowReach LateralNoVyModel::reach(double sample_period) const {
  return detail::widened(Model::reach(sample_period), brake_margin_, sample_period);
}

RowModel::RowFn LateralNoVyModel::bind(const ChannelSet& set,
                                       const std::vector<std::string>&) const {
  const Eigen::VectorXd& vx = set["vx"];
  const Eigen::VectorXd& dvx = set["d_vx"];
  const Eigen::VectorXd& ay = set["ay"];
  const Eigen::VectorXd& day = set["d_ay"];
  const Eigen::VectorXd& r = set["yaw_rate"];
  const Eigen::VectorXd& dr = set["d_yaw_rate"];
  const Eigen::VectorXd& steer = set["steer"];
  const Eigen::VectorXd& dsteer = set["d_steer"];
  const double scale = mass_.value_or(1.0);
  const std::vector<bool> braking =
      detail::near_braking(set, brake_threshold_, brake_margin_, false);
  return [=, this, &vx, &dvx, &ay, &day, &r, &dr, &steer, &dsteer](
             Eigen::Index k, std::size_t group, double* w, double& y) {
    if (vx(k) < min_speed_ || braking[static_cast<std::size_t>(k)]) return false;
    const double rho = r(k) / vx(k);
    const double stretch = dvx(k) / vx(k);  // the speed's relative rate
    if (group == 0) {
      const double drho = dr(k) / vx(k) - rho * stretch;
      const double slip_rate = ay(k) / vx(k) - r(k);
      w[0] = slip_rate - stretch * (steer(k) - a_ * rho) - dsteer(k) + a_ * drho;
      w[1] = slip_rate - stretch * b_ * rho - b_ * drho;
      y = -scale * (day(k) + stretch * ay(k));
    } else {
      w[2] = dr(k);
      w[3] = ay(k);
      y = steer(k) - (a_ + b_) * rho;
    }
    return true;
  };
}

}  // namespace dynid::model
