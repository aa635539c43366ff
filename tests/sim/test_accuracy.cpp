// Realistic accuracy: simulated runs with sensor noise, offsets, CAN quantization and every
// effect on; preprocessing as the server does it (zero-phase low-pass, central differences);
// rows from the project's models; incremental QR identification. Each parameter must be within
// its tolerance of the simulator's truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "dynid/ls/equation_groups.hpp"
#include "dynid/model/clutch_slip.hpp"
#include "dynid/model/lateral_bicycle.hpp"
#include "dynid/model/longitudinal.hpp"
#include "dynid/signal/butterworth.hpp"
#include "dynid/signal/derivative.hpp"
#include "dynid/signal/zero_phase_filter.hpp"
#include "sim_test_support.hpp"

namespace dynid::sim {
namespace {

using SimRun = dynid::sim::Run;

constexpr double kCutoffHz = 5.0;

// DYCARO's script_filtre: every channel low-passed forward-backward, derivatives by central
// differences of the filtered signal. Discrete channels (gear) pass unfiltered.
model::ChannelSet preprocess(const SimRun& r, const std::vector<std::string>& derivatives) {
  const auto n = static_cast<Eigen::Index>(r.time.size());
  const double period = r.time[1] - r.time[0];
  const auto sos = signal::butterworth_lowpass(4, kCutoffHz, 1.0 / period);
  model::ChannelSet set(period, n);
  for (std::size_t c = 0; c < r.channels.size(); ++c) {
    Eigen::VectorXd x(n);
    for (Eigen::Index k = 0; k < n; ++k) x(k) = r.measured[static_cast<std::size_t>(k)][c];
    const std::string& name = r.channels[c].name;
    const bool discrete = name == "gear" || name == "gear_ratio";
    Eigen::VectorXd filtered = discrete ? x : Eigen::VectorXd(signal::zero_phase_filter(sos, x).col(0));
    set.add(name, r.channels[c].unit, filtered);
  }
  for (const auto& name : derivatives) {
    const std::string unit = set.unit(name) == "m/s" ? "m/s^2" : "rad/s^2";
    set.add("d_" + name, unit, Eigen::VectorXd(signal::derivative(set[name], period).col(0)));
  }
  return set;
}

struct Result {
  std::vector<std::string> names;
  ls::Estimate estimate;
  double value(const std::string& n) const { return estimate.value(index(n)); }
  double std_dev(const std::string& n) const { return estimate.standard_deviation(index(n)); }
  Eigen::Index index(const std::string& n) const {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == n) return static_cast<Eigen::Index>(i);
    ADD_FAILURE() << "no parameter " << n;
    return 0;
  }
};

Result identify(const model::Model& m, const std::vector<model::ChannelSet>& runs,
                const std::vector<std::string>& effects) {
  Result out;
  for (const auto& p : m.parameters_with(effects)) out.names.push_back(p.name);
  ls::EquationGroups groups(static_cast<Eigen::Index>(out.names.size()), m.groups());
  for (const auto& set : runs)
    for (const auto& g : m.rows(set, effects))
      if (g.W.rows() > 0) groups.fold(groups.index_of(g.group), g.W, g.y);
  out.estimate = groups.estimate().estimate;
  return out;
}

struct Check {
  std::string parameter;
  double truth;
  double estimate;
  double std_dev;
  double tolerance;
};

void report_and_check(const std::string& model, const std::vector<Check>& checks) {
  std::printf("\n%-16s %-28s %14s %14s %12s %9s %6s\n", "model", "parameter", "truth", "estimate", "std", "error %",
              "tol %");
  for (const auto& c : checks) {
    const double err = 100.0 * (c.estimate - c.truth) / c.truth;
    std::printf("%-16s %-28s %14.6g %14.6g %12.4g %9.3f %6.1f\n", model.c_str(), c.parameter.c_str(), c.truth,
                c.estimate, c.std_dev, err, 100.0 * c.tolerance);
    EXPECT_LE(std::abs(err), 100.0 * c.tolerance) << model << " " << c.parameter;
    EXPECT_TRUE(std::isfinite(c.std_dev) && c.std_dev > 0.0) << model << " " << c.parameter;
  }
}

TEST(SimAccuracy, LateralBicycle) {
  const SimRun r = test::run(test::load_scenario_text("sine_steer.toml"), 11);
  const auto set = preprocess(r, {"yaw_rate"});
  const auto& v = r.scenario.car.vehicle;
  model::LateralBicycleModel m({{"a", v.cg_to_front_axle}, {"b", v.cg_to_rear_axle}, {"mass", v.mass},
                                {"imu_x", v.imu_position[0]}});
  const Result res = identify(m, {set}, {});
  const auto truth = [&](const std::string& k) { return test::truth_value(r, k); };
  report_and_check("lateral_bicycle",
                   {{"yaw_inertia", truth("vehicle.yaw_inertia"), res.value(m.parameters()[0].name),
                     res.std_dev(m.parameters()[0].name), 0.03},
                    {"front_cornering_stiffness", truth("vehicle.cornering_stiffness_front"),
                     res.value(m.parameters()[1].name), res.std_dev(m.parameters()[1].name), 0.05},
                    {"rear_cornering_stiffness", truth("vehicle.cornering_stiffness_rear"),
                     res.value(m.parameters()[2].name), res.std_dev(m.parameters()[2].name), 0.05}});
}

TEST(SimAccuracy, LongitudinalFromWheelTorque) {
  const SimRun acc = test::run(test::load_scenario_text("acceleration.toml"), 12);
  const SimRun coast = test::run(test::load_scenario_text("coast_down.toml"), 13);
  const auto& v = acc.scenario.car.vehicle;
  model::LongitudinalModel m({{"wheel_radius", v.wheel_radius}, {"air_density", v.air_density}},
                             model::LongitudinalModel::Source::kWheelTorque);
  const Result res = identify(m, {preprocess(acc, {"vx"}), preprocess(coast, {"vx"})}, {"brake_drag"});
  const auto& p = m.parameters();
  // The wheel torque accelerates the car and the spin inertia of its four wheels: the mass this
  // row identifies is M + 4 J_w / r^2 (truth: longitudinal_equivalent_mass).
  report_and_check("longitudinal",
                   {{"mass (equivalent)", test::truth_value(acc, "vehicle.longitudinal_equivalent_mass"),
                     res.value(p[0].name), res.std_dev(p[0].name), 0.01},
                    {"scx", test::truth_value(acc, "vehicle.scx"), res.value(p[1].name), res.std_dev(p[1].name), 0.05}});
}

TEST(SimAccuracy, ClutchSlip) {
  const SimRun r = test::run(test::load_scenario_text("launch.toml"), 14);
  const auto& d = r.scenario.car.driveline;
  model::ClutchSlipModel m({{"clutch_friction_radius", d.clutch_radius}, {"stribeck_speed", d.clutch_stribeck_speed},
                       // Noisy speed sensors: a stuck clutch reads a slip of a few 0.1 rad/s.
                       {"min_slip_speed", 3.0}});
  const Result res = identify(m, {preprocess(r, {"engine_speed"})},
                              {"viscous_friction", "stribeck_friction", "engine_torque_offset"});
  const auto& p = m.parameters();
  report_and_check("clutch_slip",
                   {{"engine_inertia", test::truth_value(r, "driveline.engine_inertia"), res.value(p[0].name),
                     res.std_dev(p[0].name), 0.05},
                    {"coulomb_friction", test::truth_value(r, "driveline.clutch.mu_coulomb"), res.value(p[1].name),
                     res.std_dev(p[1].name), 0.02}});
}

}  // namespace
}  // namespace dynid::sim
