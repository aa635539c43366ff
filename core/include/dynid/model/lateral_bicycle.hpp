#pragma once
// LateralBicycleModel: single-track lateral and yaw dynamics with linear tyres, mixed
// Eulerian-Lagrangian form fed by the IMU (venture §2.3 eq. L2081 and §10; nehaoua §10.1-10.2):
//
//   slip angles   d_f = steer - atan((vy + a r) / vx),   d_r = -atan((vy - b r) / vx)
//   tyres         F_yf = C_f d_f,  F_yr = C_r d_r        (axle cornering stiffness, N/rad)
//   lateral       M ay   = F_yf cos(steer) + F_yr
//   yaw           J dr/dt = a F_yf cos(steer) - b F_yr
//
// ay is the accelerometer (specific force): M ay is the tyre force whatever the road bank, so
// no grade/bank term appears; an IMU imu_x ahead of the CG reads ay + imu_x dr/dt, removed.
// The front longitudinal force term F_xf sin(steer) is neglected (small steer).
//
// Groups "lateral" and "yaw". With the optional constant `mass` (weighed, or identified by the
// longitudinal model) the parameters are [yaw_inertia, front_cornering_stiffness,
// rear_cornering_stiffness] and the lateral row is y = M ay, columns [0, d_f cos(steer), d_r];
// the yaw row is y = 0, columns [dr/dt, -a d_f cos(steer), b d_r]. Without it the equations are
// homogeneous in (M, J, C_f, C_r) (venture §10): the model then identifies the same quantities
// per unit mass (names suffixed _per_mass), with y = ay.
//
// Rows left out: vx < min_speed (slip angles undefined). Constants: a, b (m, CG to front and
// rear axle); optional mass (kg), imu_x (m, 0), min_speed (m/s, 1).
// Effects: steer_offset (an offset d0 on the steer sensor: a force C_f d0), tyre_saturation
// (|d| d terms of a Fiala tyre before saturation, nehaoua §10.3).
#include <optional>

#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class LateralBicycleModel final : public RowModel {
 public:
  explicit LateralBicycleModel(const Constants& constants);

  std::string name() const override { return "lateral_bicycle"; }
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"lateral", "yaw"}; }

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;

 private:
  struct Slip {
    double front;  // d_f
    double rear;   // d_r
    double cos_steer;
  };
  std::function<Slip(Eigen::Index)> slip(const ChannelSet& channels) const;
  // The parameter as identified: per unit mass when the mass is not known.
  ParameterInfo scaled(ParameterInfo p) const;
  // An effect whose lateral column is front(s) cos(steer) + rear(s) and yaw column
  // -a front(s) cos(steer) + b rear(s), for tyre-force-like terms.
  EffectDefinition axle_effect(Effect info, std::function<double(double)> law,
                               bool rear) const;

  double a_;
  double b_;
  std::optional<double> mass_;
  double imu_x_;
  double min_speed_;
};

}  // namespace dynid::model
