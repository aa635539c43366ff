#include "dynid/model/locked_driveline.hpp"

#include <cmath>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::non_negative;
using detail::excited;
using detail::parameter;
using detail::positive;

LockedDrivelineModel::LockedDrivelineModel(const Constants& constants) {
  const ConstantReader c(constants, "locked_driveline");
  const double gear = c.positive("gear", "the engaged gear of this model, integer >= 1");
  if (gear != std::round(gear))
    throw InputError("model 'locked_driveline': constant 'gear' = " + std::to_string(gear) +
                     " is not an integer");
  gear_ = std::lround(gear);
  slip_tolerance_ = c.positive_or("lock_slip_tolerance", 1.0);
  brake_threshold_ = detail::brake_pressure_threshold(c);
}

std::vector<ParameterInfo> LockedDrivelineModel::parameters() const {
  // The road load only takes energy: p, q, r >= 0 (a negative p says that an ECU torque
  // offset, the same column, is in the data).
  // No typical magnitude: at the engine shaft every one depends on the gear.
  const std::string load = "engine_speed over a wide range in gear (coast down)";
  return {excited(positive(parameter("equivalent_inertia", "kg m^2", "J_e + J_bv at the engine shaft")),
                  std::nullopt, "d_engine_speed in gear (accelerate, brake)"),
          excited(non_negative(
                      parameter("road_load_constant", "N m", "p: rolling resistance at the engine shaft")),
                  std::nullopt, load),
          excited(non_negative(parameter("road_load_linear", "N m s/rad", "q")), std::nullopt, load),
          excited(non_negative(parameter("road_load_quadratic", "N m s^2/rad^2", "r: aerodynamic drag")),
                  std::nullopt, load)};
}

std::vector<ChannelNeed> LockedDrivelineModel::channels() const {
  return {{"engine_speed", "rad/s"},
          {"d_engine_speed", "rad/s^2"},
          {"engine_torque", "N m"},
          {"gear", "-"},
          {"gearbox_input_speed", "rad/s", true},
          {"brake_pressure", "Pa", true},
          {"road_grade", "rad", true}};
}

std::vector<RowModel::EffectDefinition> LockedDrivelineModel::effect_definitions() const {
  return {detail::one_column({effect::kRoadGrade,
                              "grade torque (M g r_w / alpha) sin(grade)",
                              // > 0 with road_grade positive uphill (docs/CHANNELS.md).
                              {positive(parameter("grade_torque", "N m", "M g r_w / alpha"))},
                              {"road_grade"}},
                             [](const ChannelSet& set) -> detail::ValueFn {
                               const Eigen::VectorXd& grade = set["road_grade"];
                               return [&grade](Eigen::Index k) { return std::sin(grade(k)); };
                             }),
          detail::brake_drag("brake_torque_gain", "N m/Pa")};
}

RowModel::RowFn LockedDrivelineModel::bind(const ChannelSet& set,
                                           const std::vector<std::string>& effects) const {
  const Eigen::VectorXd& we = set["engine_speed"];
  const Eigen::VectorXd& dwe = set["d_engine_speed"];
  const Eigen::VectorXd& te = set["engine_torque"];
  const Eigen::VectorXd& gear = set["gear"];
  const Eigen::VectorXd* input = detail::find(set, "gearbox_input_speed");
  auto braking = detail::braking(set, brake_threshold_, enabled(effects, effect::kBrakeDrag));
  const Eigen::Index last = set.samples() - 1;
  return [=, this, &set, &we, &dwe, &te, &gear](Eigen::Index k, std::size_t, double* w,
                                                 double& y) {
    // Outside the run counts as the same gear; an invalid neighbour may hide a shift.
    const auto in_gear = [&](Eigen::Index j) {
      if (j < 0 || j > last) return true;
      return set.valid(j) && std::abs(gear(j) - static_cast<double>(gear_)) < 0.5;
    };
    if (!in_gear(k) || !in_gear(k - 1) || !in_gear(k + 1) || braking(k)) return false;
    if (input != nullptr && std::abs(we(k) - (*input)(k)) > slip_tolerance_) return false;
    w[0] = dwe(k);
    w[1] = 1.0;
    w[2] = we(k);
    w[3] = we(k) * we(k);
    y = te(k);
    return true;
  };
}

}  // namespace dynid::model
