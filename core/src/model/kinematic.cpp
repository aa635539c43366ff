#include "dynid/model/kinematic.hpp"

#include <cmath>

#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::excited;
using detail::parameter;
using detail::positive;

KinematicModel::KinematicModel(const Constants& constants, Axis axis) : axis_(axis) {
  gravity_ = ConstantReader(constants, name()).positive_or("gravity", detail::kStandardGravity);
}

std::string KinematicModel::name() const {
  return axis_ == Axis::kLongitudinal ? "kinematic_longitudinal" : "kinematic_lateral";
}

std::vector<std::string> KinematicModel::groups() const {
  return {axis_ == Axis::kLongitudinal ? "longitudinal" : "lateral"};
}

std::vector<std::string> KinematicModel::measured_side() const {
  return {axis_ == Axis::kLongitudinal ? "ax" : "ay"};
}

std::vector<ParameterInfo> KinematicModel::parameters() const {
  // The scale is a ratio of two gains near 1 (> 0: a negative one is a sensor mounted the
  // wrong way round or a sign error in the profile, not a car); the offset has either sign.
  const std::string by = axis_ == Axis::kLongitudinal ? "d_vx (accelerate, brake)"
                                                       : "d_vy + vx yaw_rate (corner)";
  // Each axis has its own accelerometer: its scale and offset are quantities of that sensor.
  const std::string sensor = measured_side().front();
  return {excited(detail::measures(positive(parameter("sensor_scale", "-",
                                                      "accelerometer gain over speed scale", 1.0)),
                                   sensor + "_sensor_scale"),
                  std::nullopt, by),
          excited(detail::measures(parameter("sensor_offset", "m/s^2", "accelerometer offset", 0.0),
                                   sensor + "_sensor_offset"),
                  std::nullopt, "time: any run")};
}

std::vector<ChannelNeed> KinematicModel::channels() const {
  if (axis_ == Axis::kLongitudinal)
    return {{"ax", "m/s^2"}, {"d_vx", "m/s^2"}, {"road_grade", "rad", true}};
  return {{"ay", "m/s^2"},
          {"d_vy", "m/s^2"},
          {"vx", "m/s"},
          {"yaw_rate", "rad/s"},
          {"road_bank", "rad", true},
          {"roll", "rad", true}};
}

std::vector<RowModel::EffectDefinition> KinematicModel::effect_definitions() const {
  const bool lon = axis_ == Axis::kLongitudinal;
  const std::string channel = lon ? "road_grade" : "road_bank";
  const double g = gravity_;
  std::vector<EffectDefinition> out{detail::one_column(
      {lon ? effect::kRoadGrade : effect::kRoadBank,
       "gravity along the axis: g sin(" + channel + ")",
       // > 0: the accelerometer reads +g sin(grade) (grade positive uphill) and +g sin(bank)
       // (bank positive raising the left side), times its own gain near 1.
       {positive(parameter(lon ? "grade_gain" : "bank_gain", "-", "gain on g sin(angle)", 1.0))},
       {channel}},
      [channel, g](const ChannelSet& set) -> detail::ValueFn {
        const Eigen::VectorXd& angle = set[channel];
        return [&angle, g](Eigen::Index k) { return g * std::sin(angle(k)); };
      })};
  if (!lon)
    out.push_back(detail::one_column(
        {effect::kRollGravity,
         "the accelerometer rolls with the body: g sin(roll) more",
         // > 0: roll positive right side down tilts the y axis to read +g sin(roll).
         {positive(parameter("roll_gravity_gain", "-", "gain on g sin(roll)", 1.0))},
         {"roll"}},
        [g](const ChannelSet& set) -> detail::ValueFn {
          const Eigen::VectorXd& roll = set["roll"];
          return [&roll, g](Eigen::Index k) { return g * std::sin(roll(k)); };
        }));
  return out;
}

RowModel::RowFn KinematicModel::bind(const ChannelSet& set,
                                     const std::vector<std::string>&) const {
  if (axis_ == Axis::kLongitudinal) {
    const Eigen::VectorXd& ax = set["ax"];
    const Eigen::VectorXd& dvx = set["d_vx"];
    return [&ax, &dvx](Eigen::Index k, std::size_t, double* w, double& y) {
      w[0] = dvx(k);
      w[1] = 1.0;
      y = ax(k);
      return true;
    };
  }
  const Eigen::VectorXd& ay = set["ay"];
  const Eigen::VectorXd& dvy = set["d_vy"];
  const Eigen::VectorXd& vx = set["vx"];
  const Eigen::VectorXd& r = set["yaw_rate"];
  return [&ay, &dvy, &vx, &r](Eigen::Index k, std::size_t, double* w, double& y) {
    w[0] = dvy(k) + r(k) * vx(k);
    w[1] = 1.0;
    y = ay(k);
    return true;
  };
}

}  // namespace dynid::model
