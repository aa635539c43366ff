#pragma once
// BodyModel: the 6x10 Newton-Euler regressor of one rigid body at the IMU point C, the body
// equation of the mixed Eulerian-Lagrangian model (venture §2.4 "[DERIVED] explicit
// single-rigid-body regressor", §2.8; Newton-Euler at the frame origin, L1391-L1393):
//
//   F = M a + dw x MS + w x (w x MS)
//   N = J dw + w x (J w) + MS x a
//
// a = (ax, ay, az) the accelerometer's specific force at C (gravity enters through it, the
// "V0dot = -g" trick, venture §9 item 7), w = gyro rates, dw = their derivatives (d_roll_rate..),
// all in body axes (x forward, y left, z up). Parameters, venture's order,
// [XX XY XZ YY YZ ZZ MX MY MZ M]: the inertia tensor at C (kg m^2), the first moments
// MS = M * (CG - C) (kg m) and the mass (kg). The measured side is the wrench the four
// dynamometric hubs apply to the body, transported to C:
//   F = sum_i F_i,   N = sum_i (N_i + p_i x F_i),   p_i = hub centre i - C (body axes).
// Groups "fx" "fy" "fz" "mx" "my" "mz" (each its own DYCARO weight). Wheel and pivot
// inertias are not identifiable with hub wrenches (venture §7 item 19) and are not modelled:
// the body is everything above the hub sensors.
//
// Constants: hub_x_<c>, hub_y_<c>, hub_z_<c> (m, c = fl fr rl rr); optional air_density
// (enables the aero_drag effect). Effects: hub_force_offset (sensor offsets of the summed hub
// forces, 3 parameters; their moments are neglected), aero_drag (SCx with 1/2 rho vx|vx| in the
// fx equation; its moment about C is left in the residual).
#include <array>
#include <optional>

#include <Eigen/Core>

#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model {

class BodyModel final : public RowModel {
 public:
  explicit BodyModel(const Constants& constants);

  std::string name() const override { return "body"; }
  std::vector<ParameterInfo> parameters() const override;
  std::vector<ChannelNeed> channels() const override;
  std::vector<std::string> groups() const override { return {"fx", "fy", "fz", "mx", "my", "mz"}; }
  std::string group_unit(const std::string& group) const override {
    return group.front() == 'f' ? "N" : "N m";
  }
  std::vector<std::string> measured_side() const override;

  /// The 6x10 regressor (venture §2.4) for specific force a, rates w, rate derivatives dw.
  static Eigen::Matrix<double, 6, 10> regressor(const Eigen::Vector3d& a, const Eigen::Vector3d& w,
                                                const Eigen::Vector3d& dw);

 protected:
  std::vector<EffectDefinition> effect_definitions() const override;
  RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const override;

 private:
  std::array<Eigen::Vector3d, 4> hub_;  // fl fr rl rr, relative to C
  std::optional<double> air_density_;
};

}  // namespace dynid::model
