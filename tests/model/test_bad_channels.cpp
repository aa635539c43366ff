// Bad channels and bad profiles: a clear InputError or a parameter reported unidentifiable by
// the base-parameter analysis, never a silently wrong estimate.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "dynid/error.hpp"
#include "dynid/model/channel_set.hpp"
#include "dynid/model/registry.hpp"
#include "model_test_support.hpp"

namespace dynid::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Throws InputError whose message contains every fragment.
template <typename F>
void expect_input_error(F&& f, std::initializer_list<const char*> fragments) {
  try {
    f();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    for (const char* s : fragments) EXPECT_NE(std::string(e.what()).find(s), std::string::npos)
        << "'" << s << "' not in: " << e.what();
  }
}

const model::Constants kLon{{"wheel_radius", 0.3}, {"air_density", 1.2}};

// Wheel-torque longitudinal data, exact, with the truth below.
model::ChannelSet longitudinal(Eigen::Index n, bool add_torque = true) {
  const Eigen::VectorXd t = time_grid(0.02, n);
  const Sines v{20.0, {5.0}, {0.3}, {0.0}};
  const Eigen::VectorXd vx = v.values(t), dvx = v.derivatives(t);
  model::ChannelSet set(0.02, n);
  set.add("vx", "m/s", vx);
  set.add("d_vx", "m/s^2", dvx);
  if (add_torque)
    set.add("wheel_torque", "N m",
            0.3 * (1400.0 * dvx + 0.6 * 0.6 * vx.cwiseAbs2() + Eigen::VectorXd::Constant(n, 150.0)));
  return set;
}

TEST(BadChannels, MissingChannelIsNamed) {
  const auto m = model::make_model("longitudinal_wheel", kLon);
  const model::ChannelSet set = longitudinal(100, false);
  EXPECT_FALSE(m->can_run_on(set));
  expect_input_error([&] { m->rows(set); }, {"longitudinal_wheel", "wheel_torque"});
}

TEST(BadChannels, EffectChannelMissingIsNamed) {
  const auto m = model::make_model("longitudinal_wheel", kLon);
  expect_input_error([&] { m->rows(longitudinal(100), {"road_grade"}); },
                     {"road_grade", "needs channel"});
}

TEST(BadChannels, WrongLengthAndDuplicateAreRejected) {
  model::ChannelSet set(0.01, 100);
  expect_input_error([&] { set.add("vx", "m/s", Eigen::VectorXd::Zero(99)); }, {"vx", "99", "100"});
  set.add("vx", "m/s", Eigen::VectorXd::Zero(100));
  expect_input_error([&] { set.add("vx", "m/s", Eigen::VectorXd::Zero(100)); }, {"duplicate"});
  expect_input_error([&] { set.invalidate(90, 20); }, {"range"});
  expect_input_error([] { model::ChannelSet(0.0, 10); }, {"sample period"});
}

TEST(BadChannels, WrongUnitIsRejected) {
  model::ChannelSet set = longitudinal(100, true);
  model::ChannelSet kmh(0.02, 100);
  kmh.add("vx", "km/h", set["vx"] * 3.6);
  kmh.add("d_vx", "m/s^2", set["d_vx"]);
  kmh.add("wheel_torque", "N m", set["wheel_torque"]);
  expect_input_error([&] { model::make_model("longitudinal_wheel", kLon)->rows(kmh); },
                     {"'vx'", "km/h", "m/s"});
}

TEST(BadChannels, NaNRunIsRejectedUnlessMarkedInvalidThenItsRowsAreLeftOut) {
  const model::ChannelSet good = longitudinal(2000);
  Eigen::VectorXd torque = good["wheel_torque"];
  torque.segment(700, 50).setConstant(kNaN);
  model::ChannelSet set(0.02, 2000);
  set.add("vx", "m/s", good["vx"]);
  set.add("d_vx", "m/s^2", good["d_vx"]);
  expect_input_error([&] { set.add("wheel_torque", "N m", torque); },
                     {"wheel_torque", "sample 700"});
  set.invalidate(700, 50);
  set.add("wheel_torque", "N m", torque);
  EXPECT_EQ(set.valid_count(), 1950);
  const auto m = model::make_model("longitudinal_wheel", kLon);
  const auto rows = m->rows(set, {"dict:lag2:vx", "dict:d:vx"});
  for (const Eigen::Index k : rows[0].samples) EXPECT_TRUE(k < 699 || k > 751) << k;
  const Identified id = identify(*m, set);
  EXPECT_EQ(id.rows, 1950u);
  EXPECT_LT(relative_error(id.value("mass"), 1400.0), 1e-6);
  EXPECT_LT(relative_error(id.value("SCx"), 0.6), 1e-6);
  EXPECT_LT(relative_error(id.value("rolling_resistance"), 150.0), 1e-6);
}

TEST(BadChannels, NonFiniteRowIsAnErrorNamingTheSample) {
  model::ChannelSet set(0.02, 10);
  Eigen::VectorXd vx = Eigen::VectorXd::Constant(10, 20.0);
  vx(4) = 1e200;  // finite, but v^2 overflows
  set.add("vx", "m/s", vx);
  set.add("d_vx", "m/s^2", Eigen::VectorXd::Zero(10));
  set.add("wheel_torque", "N m", Eigen::VectorXd::Zero(10));
  expect_input_error([&] { model::make_model("longitudinal_wheel", kLon)->rows(set); },
                     {"non-finite", "sample 4"});
}

TEST(BadChannels, ConstantSpeedLeavesMassEliminatedAndDragRegroupedNotGarbage) {
  // Cruise at constant speed: d_vx = 0 and v^2 is a constant like the rolling column.
  const Eigen::Index n = 500;
  model::ChannelSet set(0.02, n);
  set.add("vx", "m/s", Eigen::VectorXd::Constant(n, 25.0));
  set.add("d_vx", "m/s^2", Eigen::VectorXd::Zero(n));
  set.add("wheel_torque", "N m", Eigen::VectorXd::Constant(n, 0.3 * (0.6 * 0.6 * 625 + 150)));
  const Identified id = identify(*model::make_model("longitudinal_wheel", kLon), set);
  EXPECT_EQ(id.status("mass"), ls::ParameterStatus::kEliminated);
  EXPECT_TRUE(std::isnan(id.value("mass")));
  // One of the two constant columns is kept (with the other regrouped into it), not both.
  EXPECT_EQ(id.estimate.structure.rank(), 1);
  EXPECT_EQ(id.status("rolling_resistance"), ls::ParameterStatus::kDependent);
  EXPECT_TRUE(std::isnan(id.value("rolling_resistance")));
}

TEST(BadChannels, NoUsableRowIsAClearError) {
  // Stopped car: every row is below min_speed; the estimate refuses instead of inventing.
  model::ChannelSet set(0.02, 100);
  for (const char* c : {"vx", "vy"}) set.add(c, "m/s", Eigen::VectorXd::Zero(100));
  set.add("ay", "m/s^2", Eigen::VectorXd::Zero(100));
  set.add("yaw_rate", "rad/s", Eigen::VectorXd::Zero(100));
  set.add("d_yaw_rate", "rad/s^2", Eigen::VectorXd::Zero(100));
  set.add("steer", "rad", Eigen::VectorXd::Zero(100));
  const auto m = model::make_model("lateral_bicycle", {{"a", 1.1}, {"b", 1.6}, {"mass", 1500}});
  for (const auto& g : m->rows(set)) EXPECT_EQ(g.W.rows(), 0);
  EXPECT_THROW(identify(*m, set), InputError);
}

TEST(BadProfiles, MissingConstantUnknownModelAndUnknownEffectAreNamed) {
  expect_input_error([] { model::make_model("longitudinal_engine", kLon); },
                     {"longitudinal_engine", "driveline_efficiency"});
  expect_input_error([] { model::make_model("lateral_bicycle", {{"a", 1.0}}); }, {"'b'"});
  expect_input_error([] { model::make_model("clutch_slip", {{"clutch_friction_radius", -1}}); },
                     {"clutch_friction_radius", "> 0"});
  expect_input_error([] { model::make_model("locked_driveline", {{"gear", 2.5}}); },
                     {"gear", "integer"});
  expect_input_error([] { model::make_model("warp_drive", {}); }, {"warp_drive", "body"});
  const auto m = model::make_model("longitudinal_wheel", kLon);
  expect_input_error([&] { m->rows(longitudinal(50), {"flux_capacitor"}); },
                     {"flux_capacitor", "road_grade"});
  expect_input_error([&] { m->rows(longitudinal(50), {"dict:sq:vz"}); }, {"vz"});
  expect_input_error([&] { m->rows(longitudinal(50), {"linear_drag", "linear_drag"}); },
                     {"twice"});
  EXPECT_THROW(m->parameters_with({"flux_capacitor"}), InputError);
}

// The gears' ratios of an engine model that infers the gear: numbered from 1 without a hole,
// and far enough apart that a measured ratio names one gear.
TEST(BadProfiles, GearRatiosWithAHoleOrTooCloseAreRefused) {
  model::Constants c{{"wheel_radius", 0.3}, {"air_density", 1.2},  {"driveline_efficiency", 0.9},
                     {"gear_ratio_1", 8.9}, {"gear_ratio_2", 6.1}, {"gear_ratio_3", 4.5}};
  EXPECT_NO_THROW(model::make_model("longitudinal_engine", c));
  c["gear_ratio_5"] = 3.7;
  expect_input_error([&] { model::make_model("longitudinal_engine", c); },
                     {"'gear_ratio_5'", "without 'gear_ratio_4'"});
  c.erase("gear_ratio_5");
  c["gear_ratio_4"] = 4.6;  // 2 % above the third
  expect_input_error([&] { model::make_model("longitudinal_engine", c); },
                     {"4.5", "4.6", "gear_ratio_tolerance", "could be either gear"});
  c["gear_ratio_4"] = 3.7;
  c["gear_ratio_tolerance"] = -0.1;
  expect_input_error([&] { model::make_model("longitudinal_engine", c); },
                     {"gear_ratio_tolerance"});
}

TEST(BadProfiles, EveryRegisteredModelNeedsItsConstantsOrRunsWithout) {
  // Each registered model either builds from an empty profile or names what is missing.
  for (const std::string& name : model::model_names()) {
    try {
      const auto m = model::make_model(name, {});
      EXPECT_FALSE(m->parameters().empty()) << name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("missing constant"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace dynid::test
