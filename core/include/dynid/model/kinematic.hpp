#pragma once
// KinematicModel: consistency of the accelerometer with the derivative of the speeds
// (venture §4.3/§7 item 14 sensor offsets; nehaoua §10 accelerometer convention).
// The accelerometer measures specific force, so on a slope or a banked road it reads gravity
// that the wheel speeds do not see: its residual is what road grade (or bank) explains.
//
//   axis kLongitudinal ("kinematic_longitudinal"), group "longitudinal":
//       ax = s d_vx + o          (+ g sin(grade), effect road_grade)
//   axis kLateral ("kinematic_lateral"), group "lateral":
//       ay = s (d_vy + r vx) + o (+ g sin(bank), effect road_bank;
//                                 + g sin(roll), effect roll_gravity: the body-fixed
//                                 accelerometer rolls with the body)
//
// Parameters [sensor_scale s (-), sensor_offset o (m/s^2)]: s = accelerometer gain / speed
// scale (a wheel-radius error scales d_vx), a priori 1; o a priori 0. The grade (bank) effect's
// parameter is a gain, a priori 1. Constants: optional gravity (9.80665). No masking beyond
// invalid samples.
#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class KinematicModel final : public RowModel {
 public:
  enum class Axis { kLongitudinal, kLateral };
  KinematicModel(const Constants& constants, Axis axis);

  std::string name() const override;
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override;
  std::string group_unit(const std::string&) const override { return "m/s^2"; }
  std::vector<std::string> measured_side() const override;

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;

 private:
  Axis axis_;
  double gravity_;
};

}  // namespace dynid::model
