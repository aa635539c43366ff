// Candidate effects and the generic dictionary produce the columns their contracts state,
// checked by hand at chosen samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dynid/model/channel_set.hpp"
#include "dynid/model/effects.hpp"
#include "dynid/model/registry.hpp"
#include "model_test_support.hpp"

namespace dynid::test {
namespace {

// A short longitudinal set with values easy to check by hand.
model::ChannelSet small_set() {
  model::ChannelSet set(0.1, 6);
  Eigen::VectorXd vx(6), dvx(6), torque(6), grade(6), pressure(6), ax(6);
  vx << 10, -12, 14, 15, 17, 20;
  dvx << 1, 2, 3, 4, 5, 6;
  torque << 100, 200, 300, 400, 500, 600;
  grade << 0.01, 0.02, 0.03, 0.04, 0.05, 0.06;
  pressure << 0, 0, 5e5, 0, 0, 0;
  ax << 1.5, 2.5, 3.5, 4.5, 5.5, 6.5;
  set.add("vx", "m/s", vx);
  set.add("d_vx", "m/s^2", dvx);
  set.add("wheel_torque", "N m", torque);
  set.add("road_grade", "rad", grade);
  set.add("brake_pressure", "Pa", pressure);
  set.add("ax", "m/s^2", ax);
  return set;
}

const model::Constants kLon{{"wheel_radius", 0.5}, {"air_density", 1.2}, {"gravity", 10.0}};

std::size_t row_of(const model::GroupRows& g, Eigen::Index sample) {
  const auto it = std::find(g.samples.begin(), g.samples.end(), sample);
  EXPECT_NE(it, g.samples.end()) << "sample " << sample << " missing";
  return static_cast<std::size_t>(it - g.samples.begin());
}

TEST(Effects, LongitudinalBaseAndEffectColumnsByHand) {
  const auto m = model::make_model("longitudinal_wheel", kLon);
  const model::ChannelSet set = small_set();
  const std::vector<std::string> effects{"road_grade", "road_grade_accelerometer", "linear_drag"};
  const auto g = m->rows(set, effects).front();
  ASSERT_EQ(g.W.cols(), 6);
  EXPECT_EQ(g.samples, (std::vector<Eigen::Index>{0, 1, 3, 4, 5}));  // braking at 2 is masked
  const auto r = static_cast<Eigen::Index>(row_of(g, 1));
  EXPECT_DOUBLE_EQ(g.y(r), 200 / 0.5);
  EXPECT_DOUBLE_EQ(g.W(r, 0), 2.0);                   // d_vx
  EXPECT_DOUBLE_EQ(g.W(r, 1), 0.5 * 1.2 * -144.0);   // 1/2 rho vx|vx| at vx = -12
  EXPECT_DOUBLE_EQ(g.W(r, 2), -1.0);                  // sgn vx
  EXPECT_DOUBLE_EQ(g.W(r, 3), 10.0 * std::sin(0.02)); // g sin(grade)
  EXPECT_DOUBLE_EQ(g.W(r, 4), 2.5 - 2.0);             // ax - d_vx
  EXPECT_DOUBLE_EQ(g.W(r, 5), -12.0);                 // vx
  const auto names = m->parameters_with(effects);
  EXPECT_EQ(names[3].name, "grade_mass");
  EXPECT_EQ(names[5].name, "linear_drag");
  // Brake drag lets the braking row in, with the pressure as its column.
  const auto b = m->rows(set, {"brake_drag"}).front();
  EXPECT_EQ(b.samples.size(), 6u);
  EXPECT_DOUBLE_EQ(b.W(static_cast<Eigen::Index>(row_of(b, 2)), 3), 5e5);
}

TEST(Effects, DictionaryColumnsByHand) {
  const auto m = model::make_model("longitudinal_wheel", kLon);
  const model::ChannelSet set = small_set();
  const auto g =
      m->rows(set, {"dict:x:vx", "dict:sq:vx", "dict:absx:vx", "dict:sgn:vx", "dict:d:vx",
                    "dict:lag2:vx"})
          .front();
  // lag2 needs k >= 2, d (five-point) 2 <= k and k + 2 < 6, braking masks 2: row 3 remains.
  EXPECT_EQ(g.samples, (std::vector<Eigen::Index>{3}));
  const auto r = static_cast<Eigen::Index>(row_of(g, 3));
  EXPECT_DOUBLE_EQ(g.W(r, 3), 15.0);
  EXPECT_DOUBLE_EQ(g.W(r, 4), 225.0);
  EXPECT_DOUBLE_EQ(g.W(r, 5), 225.0);
  EXPECT_DOUBLE_EQ(g.W(r, 6), 1.0);
  // vx[1] - 8 vx[2] + 8 vx[4] - vx[5] over 12 T: the preprocessing's d_vx stencil.
  EXPECT_DOUBLE_EQ(g.W(r, 7), (-12.0 - 8.0 * 14.0 + 8.0 * 17.0 - 20.0) / (12.0 * 0.1));
  EXPECT_DOUBLE_EQ(g.W(r, 8), -12.0);
}

// An interaction of two channels (issue 15): dict:prod:<a>*<b> is a b, read from both channels,
// named once per pair; a malformed product is not a dictionary name.
TEST(Effects, ProductOfTwoChannels) {
  const auto m = model::make_model("longitudinal_wheel", kLon);
  const model::ChannelSet set = small_set();
  const auto g = m->rows(set, {"dict:prod:vx*ax"}).front();
  const auto r = static_cast<Eigen::Index>(row_of(g, 4));
  EXPECT_DOUBLE_EQ(g.W(r, 3), 17.0 * 5.5);
  const model::Effect e = model::dictionary_effect("dict:prod:vx*ax", {"model"});
  EXPECT_EQ(e.channels, (std::vector<std::string>{"vx", "ax"}));
  const auto all = model::dictionary_effects(set);
  // Each pair once, in the set's order of names (alphabetical: ax before vx).
  EXPECT_EQ(std::count_if(all.begin(), all.end(), [](const model::Effect& x) { return x.name == "dict:prod:ax*vx"; }), 1);
  EXPECT_EQ(std::count_if(all.begin(), all.end(), [](const model::Effect& x) { return x.name == "dict:prod:vx*ax"; }), 0);
  for (const char* bad : {"dict:prod:vx", "dict:prod:*ax", "dict:prod:vx*", "dict:prod:vx*ax*ax"})
    EXPECT_FALSE(model::is_dictionary_effect(bad)) << bad;
}

TEST(Effects, DictionaryListsEveryChannelAndExpandsPerGroup) {
  const model::ChannelSet set = small_set();
  const auto all = model::dictionary_effects(set);
  EXPECT_EQ(all.size(), 6u * 8u + 6u * 5u / 2u);  // 8 ops per channel, a product per pair
  EXPECT_TRUE(std::any_of(all.begin(), all.end(),
                          [](const model::Effect& e) { return e.name == "dict:sq:vx"; }));
  EXPECT_TRUE(model::is_dictionary_effect("dict:lag3:ax"));
  EXPECT_FALSE(model::is_dictionary_effect("dict:cube:ax"));
  EXPECT_FALSE(model::is_dictionary_effect("road_grade"));
  // A two-group model gets one coefficient per group, zero in the other group's rows.
  const auto lat = model::make_model("lateral_bicycle", {{"a", 1.0}, {"b", 1.5}, {"mass", 1000}});
  const auto params = lat->parameters_with({"dict:sq:vx"});
  ASSERT_EQ(params.size(), 5u);
  EXPECT_EQ(params[3].name, "dict:sq:vx@lateral");
  EXPECT_EQ(params[4].name, "dict:sq:vx@yaw");
  model::ChannelSet bike(0.1, 3);
  bike.add("vx", "m/s", Eigen::Vector3d(10, 11, 12));
  for (const char* c : {"vy"}) bike.add(c, "m/s", Eigen::Vector3d(0.1, 0.2, 0.3));
  bike.add("ay", "m/s^2", Eigen::Vector3d(1, 2, 3));
  bike.add("yaw_rate", "rad/s", Eigen::Vector3d(0.1, 0.1, 0.1));
  bike.add("d_yaw_rate", "rad/s^2", Eigen::Vector3d(0.0, 0.1, 0.2));
  bike.add("steer", "rad", Eigen::Vector3d(0.02, 0.03, 0.04));
  const auto rows = lat->rows(bike, {"dict:sq:vx"});
  EXPECT_DOUBLE_EQ(rows[0].W(1, 3), 121.0);
  EXPECT_DOUBLE_EQ(rows[0].W(1, 4), 0.0);
  EXPECT_DOUBLE_EQ(rows[1].W(1, 3), 0.0);
  EXPECT_DOUBLE_EQ(rows[1].W(1, 4), 121.0);
  // The slip angles by hand at sample 1 (a = 1, b = 1.5).
  const double df = 0.03 - std::atan((0.2 + 1.0 * 0.1) / 11.0);
  const double dr = -std::atan((0.2 - 1.5 * 0.1) / 11.0);
  EXPECT_DOUBLE_EQ(rows[0].W(1, 1), df * std::cos(0.03));
  EXPECT_DOUBLE_EQ(rows[1].W(1, 2), 1.5 * dr);
  EXPECT_DOUBLE_EQ(rows[0].y(1), 2000.0);
}

TEST(Effects, AntiRollBarColumnIsTheTravelDifference) {
  model::ChannelSet set(0.01, 2);
  set.add("susp_travel_rl", "m", Eigen::Vector2d(0.02, -0.01));
  set.add("susp_travel_rr", "m", Eigen::Vector2d(-0.01, 0.03));
  set.add("d_susp_travel_rl", "m/s", Eigen::Vector2d(0.1, -0.2));
  set.add("susp_force_rl", "N", Eigen::Vector2d(3000, 2000));
  const auto m = model::make_model("suspension_rl", {});
  const auto g = m->rows(set, {"anti_roll_bar", "nonlinear_damping"}).front();
  ASSERT_EQ(g.W.rows(), 2);
  EXPECT_DOUBLE_EQ(g.W(0, 4), 0.03);
  EXPECT_DOUBLE_EQ(g.W(1, 4), -0.04);
  EXPECT_DOUBLE_EQ(g.W(1, 5), -0.04);  // |v| v at v = -0.2
  EXPECT_DOUBLE_EQ(g.W(1, 2), -1.0);   // sgn v
  const auto effects = m->candidate_effects();
  EXPECT_TRUE(std::any_of(effects.begin(), effects.end(), [](const model::Effect& e) {
    return e.name == "anti_roll_bar" && e.channels == std::vector<std::string>{"susp_travel_rr"};
  }));
}

// The bicycle model has no longitudinal tyre force (lateral_bicycle.hpp): braking rows, and
// those within brake_margin of one, are left out of both groups.
TEST(Effects, LateralBicycleLeavesOutBrakingRows) {
  model::ChannelSet set(0.1, 6);
  Eigen::VectorXd pressure(6);
  pressure << 0, 0, 5e5, 0, 0, 0;
  for (const char* c : {"vx", "vy"}) set.add(c, "m/s", Eigen::VectorXd::Constant(6, 10.0));
  set.add("ay", "m/s^2", Eigen::VectorXd::Constant(6, 1.0));
  set.add("yaw_rate", "rad/s", Eigen::VectorXd::Constant(6, 0.1));
  set.add("d_yaw_rate", "rad/s^2", Eigen::VectorXd::Constant(6, 0.01));
  set.add("steer", "rad", Eigen::VectorXd::Constant(6, 0.05));
  set.add("brake_pressure", "Pa", pressure);
  const auto lat = model::make_model("lateral_bicycle", {{"a", 1.0}, {"b", 1.5}, {"mass", 1000}});
  for (const model::GroupRows& g : lat->rows(set))
    EXPECT_EQ(g.samples, (std::vector<Eigen::Index>{0, 1, 3, 4, 5}));
  const auto margin = model::make_model(
      "lateral_bicycle", {{"a", 1.0}, {"b", 1.5}, {"mass", 1000}, {"brake_margin", 0.1}});
  for (const model::GroupRows& g : margin->rows(set))
    EXPECT_EQ(g.samples, (std::vector<Eigen::Index>{0, 4, 5}));
}

}  // namespace
}  // namespace dynid::test
