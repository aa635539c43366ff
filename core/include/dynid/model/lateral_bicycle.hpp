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
// The front longitudinal force term F_xf sin(steer) is neglected where the car does not brake
// (small steer and drive force: measured 0.2 %; braking rows are left out, below).
// Roll: a body-fixed accelerometer on a body rolled by phi reads ay cos(phi) + az sin(phi), i.e.
// g phi more than the road-plane ay. With a roll gradient of ~0.006 rad per m/s^2 that is ~6 % of
// ay, all of it a scale error on C_f, C_r and J (found on the reference simulator: +6..8 % with
// the tyres linear). When the optional channel `roll` (body roll to the road, rad) is present the
// lateral row uses ay cos(roll) - az sin(roll) (az when present, else gravity): no parameter.
// The part of the lateral force that accelerates the unsprung masses (they do not roll with the
// body, so the body IMU misses m_u h d2phi/dt2) is not modelled: about +1 % on this car.
//
// Groups "lateral" and "yaw". With the optional constant `mass` (weighed, or identified by the
// longitudinal model) the parameters are [yaw_inertia, front_cornering_stiffness,
// rear_cornering_stiffness] and the lateral row is y = M ay, columns [0, d_f cos(steer), d_r];
// the yaw row is y = 0, columns [dr/dt, -a d_f cos(steer), b d_r]. Without it the equations are
// homogeneous in (M, J, C_f, C_r) (venture §10): the model then identifies the same quantities
// per unit mass (names suffixed _per_mass), with y = ay.
//
// Rows left out: vx < min_speed (slip angles undefined); braking (brake_pressure >
// brake_pressure_threshold, and within brake_margin of it), because the model has no
// longitudinal tyre force: braked front wheels turned by the steer push the car sideways by
// F_xf sin(steer) and turn it by a F_xf sin(steer), and the load the braking moves forward
// changes both axles' cornering stiffness (on an independent car's steering run with the speed
// cycled by throttle and brakes, F_xf sin(steer) at 2.5 m/s^2 and 2-3 deg of steer is about 3 %
// of the tyre forces: the yaw residual stood 10-25 % above its noise floor, correlated with the
// brake pressure). Constants: a, b (m, CG to front and rear axle); optional mass (kg), imu_x
// (m, 0), min_speed (m/s, 1), brake_pressure_threshold (Pa, 2e4) and brake_margin (s, 0) as the
// longitudinal model's (longitudinal.hpp).
// Effects: steer_offset (an offset d0 on the steer sensor: a force C_f d0), slip_offset
// (constant slip-angle offsets e_f, e_r on both axles: forces C_f e_f, C_r e_r; at a steady speed
// the steer, vy and yaw-rate sensor offsets all shift the slip angles by constants, and a few
// mrad of steer offset against a 0.02 rad slip angle cost -5 % on C_f; it contains steer_offset,
// enable one of the two), tyre_saturation (|d| d terms of a Fiala tyre before saturation,
// nehaoua §10.3; a 0.03 rad slip is already 13 % below the linear force), roll_acceleration
// (columns d_roll_rate in both rows: roll_lateral_moment, kg m, and roll_yaw_product, kg m^2).
// Why roll_acceleration: the body rolls about an axis near the ground; the IMU on the body reads
// the acceleration of its own point, which the roll acceleration moves by h d2phi/dt2, while the
// unsprung masses (~10 % of the car) do not roll, so M ay misses (or adds) about m_u h d2phi/dt2;
// and a sprung mass with a product of inertia J_xz couples roll into yaw. Both grow with the
// square of the frequency: on the reference simulator's sine sweep to 2 Hz (roll gradient 0.006
// rad per m/s^2, IMU at the sprung CG 0.55 m up) they cost +3..+5 % on C_r and +1..2 % on J
// (sensors quiet: C_r +4.4 %); with the effect, within 1.5 %. roll_rate is the body gyro; its
// derivative d_roll_rate is made by the server like any d_ channel.
// Optional channels: roll, az (see above).
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
  /// Per unit mass without a mass: ay (m/s^2) and the yaw moment over the mass (m^2/s^2).
  std::string group_unit(const std::string& group) const override {
    if (group == "lateral") return mass_ ? "N" : "m/s^2";
    return mass_ ? "N m" : "m^2/s^2";
  }
  std::vector<std::string> measured_side() const override { return {"ay"}; }

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;
  RowReach reach(double sample_period) const override;

 private:
  struct Slip {
    double front;  // d_f
    double rear;   // d_r
    double cos_steer;
  };
  std::function<Slip(Eigen::Index)> slip(const ChannelSet& channels) const;
  // The lateral specific force in the road plane: ay itself, or with `roll` present the
  // accelerometer turned back through the body's roll angle.
  std::function<double(Eigen::Index)> road_plane_ay(const ChannelSet& channels) const;
  // The parameter as identified: per unit mass when the mass is not known.
  ParameterInfo scaled(ParameterInfo p) const;
  // An effect whose lateral column is front(s) cos(steer) + rear(s) and yaw column
  // -a front(s) cos(steer) + b rear(s), for tyre-force-like terms.
  EffectDefinition axle_effect(Effect info, std::function<double(double)> law,
                               bool rear) const;
  EffectDefinition roll_acceleration() const;

  double a_;
  double b_;
  std::optional<double> mass_;
  double imu_x_;
  double min_speed_;
  double gravity_;
  double brake_threshold_;
  double brake_margin_;
};

}  // namespace dynid::model
