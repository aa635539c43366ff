// Physical bounds of the parameters (ParameterInfo::lower/upper): the edges and NaN of
// within_bounds, the one-line text, every registered model's bounds (and its candidate
// effects') consistent, and the bounds that the sign conventions fix pinned.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynid/model/effects.hpp"
#include "dynid/model/model.hpp"
#include "dynid/model/registry.hpp"

namespace dynid::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Constants enough for every registered model (and every optional effect: air_density gives
// the body its aero_drag, stribeck_speed the clutch its stribeck_friction).
model::Constants all_constants(bool with_mass) {
  model::Constants c{{"wheel_radius", 0.31},         {"air_density", 1.2},
                     {"driveline_efficiency", 0.92}, {"a", 1.09},
                     {"b", 1.6},                     {"clutch_friction_radius", 0.05},
                     {"stribeck_speed", 0.2},        {"gear", 2.0}};
  for (const char* corner : {"fl", "fr", "rl", "rr"})
    for (const char* axis : {"x", "y", "z"}) c[std::string("hub_") + axis + "_" + corner] = 0.5;
  if (with_mass) c["mass"] = 1500.0;
  return c;
}

// Every parameter of the model and of all its candidate effects, named "model/parameter".
std::map<std::string, model::ParameterInfo> all_parameters(bool with_mass) {
  std::map<std::string, model::ParameterInfo> out;
  for (const std::string& name : model::model_names()) {
    const auto m = model::make_model(name, all_constants(with_mass));
    std::vector<model::ParameterInfo> ps = m->parameters();
    for (const model::Effect& e : m->candidate_effects())
      ps.insert(ps.end(), e.parameters.begin(), e.parameters.end());
    for (const model::ParameterInfo& p : ps) out[name + "/" + p.name] = p;
  }
  return out;
}

model::ParameterInfo with(std::optional<double> lower, bool lower_inclusive,
                          std::optional<double> upper, bool upper_inclusive) {
  model::ParameterInfo p{"x", "-", "", std::nullopt};
  p.lower = lower;
  p.upper = upper;
  p.lower_inclusive = lower_inclusive;
  p.upper_inclusive = upper_inclusive;
  return p;
}

TEST(ParameterBounds, NoBoundsAcceptEverything) {
  const model::ParameterInfo p{"offset", "N", "", 0.0};
  EXPECT_EQ(p.bounds_text(), "");
  for (double v : {-kInf, -1e300, 0.0, 1e300, kInf, kNaN}) EXPECT_TRUE(p.within_bounds(v)) << v;
}

TEST(ParameterBounds, EdgesFollowInclusiveness) {
  const model::ParameterInfo positive = with(0.0, false, std::nullopt, true);
  EXPECT_EQ(positive.bounds_text(), "> 0");
  EXPECT_FALSE(positive.within_bounds(0.0));
  EXPECT_FALSE(positive.within_bounds(-0.0));
  EXPECT_FALSE(positive.within_bounds(-1e-300));
  EXPECT_TRUE(positive.within_bounds(std::nextafter(0.0, 1.0)));
  EXPECT_TRUE(positive.within_bounds(kInf));
  EXPECT_FALSE(positive.within_bounds(-kInf));

  const model::ParameterInfo non_negative = with(0.0, true, std::nullopt, true);
  EXPECT_EQ(non_negative.bounds_text(), ">= 0");
  EXPECT_TRUE(non_negative.within_bounds(0.0));
  EXPECT_FALSE(non_negative.within_bounds(std::nextafter(0.0, -1.0)));

  const model::ParameterInfo non_positive = with(std::nullopt, false, 0.0, true);
  EXPECT_EQ(non_positive.bounds_text(), "<= 0");
  EXPECT_TRUE(non_positive.within_bounds(0.0));
  EXPECT_FALSE(non_positive.within_bounds(std::nextafter(0.0, 1.0)));
  EXPECT_FALSE(with(std::nullopt, false, 1.5, false).within_bounds(1.5));
  EXPECT_EQ(with(std::nullopt, false, 1.5, false).bounds_text(), "< 1.5");

  const model::ParameterInfo drag = with(0.0, false, 2.0, true);
  EXPECT_EQ(drag.bounds_text(), "(0, 2]");
  EXPECT_TRUE(drag.within_bounds(2.0));
  EXPECT_FALSE(drag.within_bounds(std::nextafter(2.0, 3.0)));
  EXPECT_TRUE(drag.within_bounds(0.65));
  EXPECT_FALSE(drag.within_bounds(kInf));
  EXPECT_EQ(with(-0.5, true, 1e6, false).bounds_text(), "[-0.5, 1e+06)");
}

TEST(ParameterBounds, NaNIsNotOutOfBounds) {
  // Not identifiable (an eliminated parameter's NaN) is not implausible.
  for (const auto& p : {with(0.0, false, std::nullopt, true), with(0.0, false, 2.0, true),
                        with(std::nullopt, false, 0.0, true)})
    EXPECT_TRUE(p.within_bounds(kNaN)) << p.bounds_text();
}

// (a) Every registered model, with and without the lateral model's mass: every bound is a
// finite number, lower < upper, the text says it, and within_bounds behaves at both edges.
TEST(ParameterBounds, EveryModelsBoundsAreConsistentAtTheEdges) {
  for (bool with_mass : {true, false})
    for (const auto& [name, p] : all_parameters(with_mass)) {
      SCOPED_TRACE(name + " " + p.bounds_text());
      EXPECT_TRUE(p.within_bounds(kNaN));
      EXPECT_EQ(p.bounds_text().empty(), !p.lower && !p.upper);
      if (p.lower && p.upper) {
        EXPECT_LT(*p.lower, *p.upper);
      }
      if (p.lower) {
        ASSERT_TRUE(std::isfinite(*p.lower));
        EXPECT_EQ(p.within_bounds(*p.lower), p.lower_inclusive);
        EXPECT_FALSE(p.within_bounds(std::nextafter(*p.lower, -kInf)));  // (c) just outside
        EXPECT_TRUE(p.within_bounds(std::nextafter(*p.lower, kInf)));
        EXPECT_FALSE(p.within_bounds(-kInf));
      }
      if (p.upper) {
        ASSERT_TRUE(std::isfinite(*p.upper));
        EXPECT_EQ(p.within_bounds(*p.upper), p.upper_inclusive);
        EXPECT_FALSE(p.within_bounds(std::nextafter(*p.upper, kInf)));  // (c) just outside
        EXPECT_TRUE(p.within_bounds(std::nextafter(*p.upper, -kInf)));
        EXPECT_FALSE(p.within_bounds(kInf));
      }
      if (p.a_priori) {
        EXPECT_TRUE(p.within_bounds(*p.a_priori)) << "a priori " << *p.a_priori;
      }
    }
}

// The bounds the models' sign conventions fix (docs/CHANNELS.md "Parameter bounds"): a change
// here is a change of physics and of that table. "" pins a parameter that must stay unbounded.
TEST(ParameterBounds, DeclaredBoundsOfEveryModel) {
  const std::map<std::string, std::string> expected{
      {"longitudinal_engine/mass", "> 0"},
      {"longitudinal_engine/SCx", "(0, 2]"},
      {"longitudinal_engine/rolling_resistance", ">= 0"},
      {"longitudinal_engine/grade_mass", "> 0"},
      {"longitudinal_engine/grade_mass_accelerometer", "> 0"},
      {"longitudinal_engine/linear_drag", ">= 0"},
      {"longitudinal_engine/brake_force_gain", ">= 0"},
      {"longitudinal_engine/engine_torque_offset", ""},
      {"longitudinal_engine/engine_inertia", "> 0"},
      {"longitudinal_wheel/mass", "> 0"},
      {"longitudinal_wheel/SCx", "(0, 2]"},
      {"lateral_bicycle/yaw_inertia", "> 0"},
      {"lateral_bicycle/front_cornering_stiffness", "> 0"},
      {"lateral_bicycle/rear_cornering_stiffness", "> 0"},
      {"lateral_bicycle/steer_offset_force", ""},
      {"lateral_bicycle/front_slip_offset_force", ""},
      {"lateral_bicycle/rear_slip_offset_force", ""},
      {"lateral_bicycle/front_tyre_saturation", "<= 0"},
      {"lateral_bicycle/rear_tyre_saturation", "<= 0"},
      {"lateral_bicycle/roll_lateral_moment", ""},
      {"lateral_bicycle/roll_yaw_product", ""},
      {"lateral_bicycle_no_vy/front_cornering_stiffness", "> 0"},
      {"lateral_bicycle_no_vy/rear_cornering_stiffness", "> 0"},
      {"lateral_bicycle_no_vy/steer_per_yaw_acceleration", "> 0"},
      {"lateral_bicycle_no_vy/understeer_gradient", ""},
      {"kinematic_longitudinal/sensor_scale", "> 0"},
      {"kinematic_longitudinal/sensor_offset", ""},
      {"kinematic_longitudinal/grade_gain", "> 0"},
      {"kinematic_lateral/bank_gain", "> 0"},
      {"kinematic_lateral/roll_gravity_gain", "> 0"},
      {"body/XX", "> 0"},
      {"body/XY", ""},
      {"body/YY", "> 0"},
      {"body/ZZ", "> 0"},
      {"body/MX", ""},
      {"body/M", "> 0"},
      {"body/SCx", "(0, 2]"},
      {"body/force_offset_x", ""},
      {"suspension_fl/stiffness", "> 0"},
      {"suspension_fl/damping", ">= 0"},
      {"suspension_fl/dry_friction", ">= 0"},
      {"suspension_fl/force_offset", ""},
      {"suspension_rr/anti_roll_bar_stiffness", ">= 0"},
      {"suspension_rr/quadratic_damping", ""},
      {"suspension_rr/cubic_stiffness", ""},
      {"tyre_fl/vertical_stiffness", "> 0"},
      {"tyre_fl/force_offset", ""},
      {"tyre_fl/tyre_damping", ">= 0"},
      {"tyre_fl/quadratic_stiffness", ""},
      {"clutch_slip/engine_inertia", "> 0"},
      {"clutch_slip/coulomb_friction", "(0, 2]"},
      {"clutch_slip/viscous_friction", ""},
      {"clutch_slip/stribeck_friction", ""},
      {"clutch_slip/engine_torque_offset", ""},
      {"clutch_torque_curve/engine_inertia", "> 0"},
      {"clutch_torque_curve/clutch_torque_1", ">= 0"},
      {"clutch_torque_curve/clutch_torque_4", ">= 0"},
      {"clutch_torque_curve/engine_torque_offset", ""},
      {"locked_driveline/equivalent_inertia", "> 0"},
      {"locked_driveline/road_load_constant", ">= 0"},
      {"locked_driveline/road_load_linear", ">= 0"},
      {"locked_driveline/road_load_quadratic", ">= 0"},
      {"locked_driveline/grade_torque", "> 0"},
      {"locked_driveline/brake_torque_gain", ">= 0"}};
  const auto all = all_parameters(true);
  for (const auto& [name, text] : expected) {
    const auto it = all.find(name);
    ASSERT_NE(it, all.end()) << name;
    EXPECT_EQ(it->second.bounds_text(), text) << name;
  }
  // Without a known mass the lateral model's quantities are per unit mass: same signs.
  const auto per_mass = all_parameters(false);
  for (const char* p : {"yaw_inertia", "front_cornering_stiffness", "rear_cornering_stiffness"})
    EXPECT_EQ(per_mass.at(std::string("lateral_bicycle/") + p + "_per_mass").bounds_text(), "> 0");
  EXPECT_EQ(per_mass.at("lateral_bicycle/front_tyre_saturation_per_mass").bounds_text(), "<= 0");
}

// (c) Values a car cannot have are reported out; ones it has are in.
TEST(ParameterBounds, ImpossibleValuesAreOut) {
  const auto all = all_parameters(true);
  EXPECT_FALSE(all.at("longitudinal_engine/mass").within_bounds(-1500.0));
  EXPECT_TRUE(all.at("longitudinal_engine/mass").within_bounds(1500.0));
  EXPECT_FALSE(all.at("longitudinal_engine/SCx").within_bounds(2.5));
  EXPECT_FALSE(all.at("longitudinal_engine/SCx").within_bounds(0.0));
  EXPECT_FALSE(all.at("clutch_slip/coulomb_friction").within_bounds(0.0));
  EXPECT_FALSE(all.at("suspension_fl/damping").within_bounds(-1.0));
  EXPECT_TRUE(all.at("suspension_fl/damping").within_bounds(0.0));
  EXPECT_FALSE(all.at("lateral_bicycle/rear_cornering_stiffness").within_bounds(-90000.0));
  EXPECT_FALSE(all.at("lateral_bicycle/front_tyre_saturation").within_bounds(1e5));
}

// Dictionary terms are whatever the residual needs: never bounded.
TEST(ParameterBounds, DictionaryTermsHaveNoBounds) {
  model::ChannelSet set(0.01, 4);
  set.add("vx", "m/s", Eigen::VectorXd::Constant(4, 10.0));
  for (const model::Effect& e : model::dictionary_effects(set))
    for (const model::ParameterInfo& p : e.parameters) {
      EXPECT_FALSE(p.lower || p.upper) << p.name;
      EXPECT_EQ(p.bounds_text(), "") << p.name;
    }
}

}  // namespace
}  // namespace dynid::test
