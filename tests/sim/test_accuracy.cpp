// Realistic accuracy: simulated runs with sensor noise, offsets, CAN quantization and every
// effect on; preprocessing as the server does it (zero-phase low-pass, central differences);
// rows from the project's models; incremental QR identification. Each parameter must be within
// its tolerance of the simulator's truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// Zero-phase low-pass cut-off (Hz) of the manoeuvres whose dynamics reach ~2 Hz (sine steer
// sweep to 2 Hz, throttle variation at 1.3 Hz, launches). A coast-down is a slow decay (time
// constant ~1 min): its cut-off is 1 Hz, because the regressor d_vx is a differentiated noisy
// speed whose noise grows as cut-off^1.5 and, being in a column, biases the mass low
// (errors in variables; docs/ACCURACY.md).
constexpr double kCutoffHz = 5.0;
constexpr double kCoastDownCutoffHz = 1.0;

// Channels the server derives before building rows (docs/CHANNELS.md):
//  - vx: the mean of the four wheel speeds (each has its own sensor noise, so the mean is
//    half as noisy as one speed signal, and the ESP's VehSpeed is no better than one);
//  - roll: body roll angle to the road from the suspension travels and tyre deflections,
//    roll = ((s_r - s_l) + (d_r - d_l)) / track, averaged over both axles.
void add_derived(const SimRun& r, model::ChannelSet& set) {
  const auto& v = r.scenario.car.vehicle;
  const auto axle_roll = [&](const char* left, const char* right, double track) -> Eigen::VectorXd {
    const std::string l(left), rr(right);
    return ((set["susp_travel_" + rr] - set["susp_travel_" + l]) +
            (set["tyre_deflection_" + rr] - set["tyre_deflection_" + l])) / track;
  };
  set.add("roll", "rad", 0.5 * (axle_roll("fl", "fr", v.track_front) + axle_roll("rl", "rr", v.track_rear)));
}

Eigen::VectorXd wheel_mean(const model::ChannelSet& set) {
  return 0.25 * (set["wheel_speed_fl"] + set["wheel_speed_fr"] + set["wheel_speed_rl"] + set["wheel_speed_rr"]);
}

// DYCARO's script_filtre: every channel low-passed forward-backward, derivatives by central
// differences of the filtered signal. Discrete channels (gear) pass unfiltered.
model::ChannelSet preprocess(const SimRun& r, const std::vector<std::string>& derivatives,
                             double cutoff_hz = kCutoffHz) {
  const auto n = static_cast<Eigen::Index>(r.time.size());
  const double period = r.time[1] - r.time[0];
  const auto sos = signal::butterworth_lowpass(4, cutoff_hz, 1.0 / period);
  model::ChannelSet filtered_set(period, n);
  for (std::size_t c = 0; c < r.channels.size(); ++c) {
    Eigen::VectorXd x(n);
    for (Eigen::Index k = 0; k < n; ++k) x(k) = r.measured[static_cast<std::size_t>(k)][c];
    const std::string& name = r.channels[c].name;
    const bool discrete = name == "gear" || name == "gear_ratio";
    Eigen::VectorXd filtered = discrete ? x : Eigen::VectorXd(signal::zero_phase_filter(sos, x).col(0));
    filtered_set.add(name, r.channels[c].unit, filtered);
  }
  model::ChannelSet set(period, n);
  for (const auto& name : filtered_set.names())
    set.add(name, filtered_set.unit(name), name == "vx" ? wheel_mean(filtered_set) : filtered_set[name]);
  add_derived(r, set);
  for (const auto& name : derivatives) {
    const std::string unit = set.unit(name) == "m/s" ? "m/s^2" : "rad/s^2";
    set.add("d_" + name, unit, Eigen::VectorXd(signal::derivative(set[name], period).col(0)));
  }
  return set;
}

// Seeds: the committed ones, shifted by DYNID_ACCURACY_SEED_SHIFT (e.g. 100) to check that the
// results do not depend on one draw of noise and offsets.
std::uint64_t seed(std::uint64_t base) {
  const char* shift = std::getenv("DYNID_ACCURACY_SEED_SHIFT");
  return base + (shift != nullptr ? std::strtoull(shift, nullptr, 10) : 0U);
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
  const SimRun r = test::run(test::load_scenario_text("sine_steer.toml"), seed(11));
  const auto set = preprocess(r, {"yaw_rate"});
  const auto& v = r.scenario.car.vehicle;
  model::LateralBicycleModel m({{"a", v.cg_to_front_axle}, {"b", v.cg_to_rear_axle}, {"mass", v.mass},
                                {"imu_x", v.imu_position[0]}});
  // The roll channel turns the accelerometer back to the road plane (it reads g sin(roll), ~6 %
  // of ay on this car); tyre_saturation is the Fiala |d| d term (13 % of the front force at the
  // peak slip of this run); slip_offset takes the steer, vy and yaw-rate sensor offsets.
  const Result res = identify(m, {set}, {"tyre_saturation", "slip_offset"});
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
  const SimRun acc = test::run(test::load_scenario_text("acceleration.toml"), seed(12));
  const SimRun coast = test::run(test::load_scenario_text("coast_down.toml"), seed(13));
  const auto& v = acc.scenario.car.vehicle;
  model::LongitudinalModel m({{"wheel_radius", v.wheel_radius}, {"air_density", v.air_density}},
                             model::LongitudinalModel::Source::kWheelTorque);
  const Result res = identify(m, {preprocess(acc, {"vx"}), preprocess(coast, {"vx"}, kCoastDownCutoffHz)},
                              {"brake_drag"});
  const auto& p = m.parameters();
  // The wheel torque accelerates the car and the spin inertia of its four wheels: the mass this
  // row identifies is M + 4 J_w / r^2 (truth: longitudinal_equivalent_mass).
  report_and_check("longitudinal",
                   {{"mass (equivalent)", test::truth_value(acc, "vehicle.longitudinal_equivalent_mass"),
                     res.value(p[0].name), res.std_dev(p[0].name), 0.01},
                    {"scx", test::truth_value(acc, "vehicle.scx"), res.value(p[1].name), res.std_dev(p[1].name), 0.05}});
}

TEST(SimAccuracy, ClutchSlip) {
  const SimRun r = test::run(test::load_scenario_text("launch.toml"), seed(14));
  const auto& d = r.scenario.car.driveline;
  model::ClutchSlipModel m({{"clutch_friction_radius", d.clutch_radius}, {"stribeck_speed", d.clutch_stribeck_speed},
                       // Noisy speed sensors (0.5 rad/s): a stuck clutch reads a slip of up to
                       // ~2 rad/s; and no row whose low-pass window (about 2 / cut-off) reaches
                       // a stuck sample, where the friction law does not hold.
                       {"min_slip_speed", 2.0}, {"stick_margin", 2.0 / kCutoffHz}});
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
