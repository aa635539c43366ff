// The reference simulator: determinism, physics sanity, effect switches, CAN round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <dynid/can/candump.hpp>
#include <dynid/can/decoder.hpp>

#include "dynid/error.hpp"
#include "dynid/sim/can_bus.hpp"
#include "dynid/sim/outputs.hpp"
#include "dynid/sim/sensors.hpp"
#include "sim_test_support.hpp"

namespace dynid::sim {
namespace {

using SimRun = dynid::sim::Run;
using test::column;
using test::run;
using test::truth_value;

const std::string kQuiet = "[effects]\nsensor_noise = false\nsensor_offsets = false\nquantization = false\n";

std::string step_steer(double speed, double steer, const std::string& extra = "") {
  return "[run]\nduration = 12.0\n[manoeuvre]\ntype = \"step_steer\"\nspeed = " + std::to_string(speed) +
         "\ngear = 4\nstart_time = 1.0\namplitude = " + std::to_string(steer) + "\n" + extra;
}

const std::string kCoastDown = "[run]\nduration = 60.0\n[manoeuvre]\ntype = \"coast_down\"\nspeed = 33.0\ngear = 0\n";

TEST(SimDeterminism, SameSeedSameRunOtherSeedOtherNoise) {
  const std::string sc = "[run]\nduration = 6.0\n[manoeuvre]\ntype = \"sine_steer\"\nspeed = 20.0\ngear = 4\n"
                         "start_time = 0.5\namplitude = 0.02\nsweep_time = 5.0\n";
  const SimRun a = run(sc, 3);
  const SimRun b = run(sc, 3);
  const SimRun c = run(sc, 4);
  EXPECT_EQ(a.measured, b.measured);
  EXPECT_EQ(a.truth, b.truth);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i)
    ASSERT_EQ(can::format_candump_line(a.frames[i]), can::format_candump_line(b.frames[i])) << i;
  EXPECT_EQ(a.truth, c.truth);        // the physics does not depend on the seed
  EXPECT_NE(a.measured, c.measured);  // the sensors do
}

// Steady-state cornering: r/delta = v / (L + K_us v^2) (nehaoua §2.4) with the truth's K_us.
double steady_yaw_rate_error(const std::string& scenario_text, double speed, double steer) {
  const SimRun r = run(scenario_text);
  const double l = truth_value(r, "vehicle.wheelbase");
  const double k_us = truth_value(r, "vehicle.understeer_gradient");
  const double expected = speed * steer / (l + k_us * speed * speed);
  const double got = column(r, "yaw_rate").back();
  return (got - expected) / expected;
}

TEST(SimPhysics, SteadyCorneringMatchesLinearBicycleWithLinearTyres) {
  // Without load transfer the planar car is the bicycle (up to the track's tiny kinematics).
  const std::string linear = kQuiet + "tyre_saturation = false\n";
  const double exact = steady_yaw_rate_error(step_steer(20.0, 0.015, linear + "load_transfer = false\n"), 20.0, 0.015);
  EXPECT_LT(std::abs(exact), 0.002) << "relative yaw-rate error " << exact;
  // With it, the degressive tyres lose axle stiffness (more at the rear: more understeer) and
  // the outer tyres' rolling resistance yaws the car: below the bicycle, by about 1 %.
  const double full = steady_yaw_rate_error(step_steer(20.0, 0.015, linear), 20.0, 0.015);
  EXPECT_LT(full, 0.0);
  EXPECT_GT(full, -0.015) << "relative yaw-rate error " << full;
}

TEST(SimPhysics, SteadyCorneringMatchesLinearBicycleAtSmallSlipWithFiala) {
  // Fiala has no exactly linear zone (nehaoua §2.6): at a_y ~ 0.6 m/s^2 it is within 1.5 %.
  const double e = steady_yaw_rate_error(step_steer(20.0, 0.004, kQuiet), 20.0, 0.004);
  EXPECT_LT(std::abs(e), 0.015) << "relative yaw-rate error " << e;
}

TEST(SimPhysics, SaturationLowersTheYawRateAtHighLateralAcceleration) {
  const double e = steady_yaw_rate_error(step_steer(20.0, 0.04, kQuiet), 20.0, 0.04);
  EXPECT_LT(e, -0.05) << "a saturating tyre must fall below the linear bicycle";
}

// Coast-down: M_eq dv/dt = -(F0 + c v^2), integrated here independently from the truth file.
TEST(SimPhysics, CoastDownFollowsTheRoadLoadOde) {
  const SimRun r = run(kCoastDown + kQuiet);
  const double m = truth_value(r, "vehicle.longitudinal_equivalent_mass");
  const double f0 = truth_value(r, "vehicle.road_load_constant_force");
  const double c = truth_value(r, "vehicle.aero_coefficient");
  const auto vx = column(r, "vx");
  double v = vx.front();
  const double dt = 1e-3;
  double worst = 0.0;
  for (std::size_t k = 1; k < vx.size(); ++k) {
    for (int i = 0; i < 10; ++i) {
      auto f = [&](double u) { return -(f0 + c * u * u) / m; };
      const double k1 = f(v), k2 = f(v + 0.5 * dt * k1), k3 = f(v + 0.5 * dt * k2), k4 = f(v + dt * k3);
      v += dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    worst = std::max(worst, std::abs(vx[k] - v));
  }
  EXPECT_GT(vx.front() - vx.back(), 10.0);
  EXPECT_LT(worst, 0.02) << "largest speed difference to the ODE, m/s";
}

// Yaw balance: Izz dr/dt = sum x_i Fy_i - y_i Fx_i, from the channels the run writes.
TEST(SimPhysics, YawMomentOfTheHubForcesMatchesTheYawAcceleration) {
  const SimRun r = run("[run]\nduration = 8.0\n[manoeuvre]\ntype = \"sine_steer\"\nspeed = 20.0\ngear = 4\n"
                    "start_time = 0.5\namplitude = 0.03\nfrequency_start = 0.5\nfrequency_end = 1.5\n"
                    "sweep_time = 7.0\n" + kQuiet);
  const auto& v = r.scenario.car.vehicle;
  const auto yaw = column(r, "yaw_rate");
  const double dt = r.time[1] - r.time[0];
  double err = 0.0, norm = 0.0;
  for (std::size_t k = 1; k + 1 < yaw.size(); ++k) {
    double moment = 0.0;
    for (int i = 0; i < kCorners; ++i) {
      const std::string w = kCornerNames[static_cast<std::size_t>(i)];
      moment += v.corner_x(i) * r.truth[k][channel_index("hub_fy_" + w)] -
                v.corner_y(i) * r.truth[k][channel_index("hub_fx_" + w)];
    }
    const double lhs = v.yaw_inertia * (yaw[k + 1] - yaw[k - 1]) / (2 * dt);
    err += (lhs - moment) * (lhs - moment);
    norm += moment * moment;
  }
  EXPECT_LT(std::sqrt(err / norm), 0.02);
}

// What each switch may change. Returns the largest |difference| of a channel between two runs.
double max_difference(const SimRun& a, const SimRun& b, const std::string& channel, bool truth = true) {
  const auto x = column(a, channel, truth);
  const auto y = column(b, channel, truth);
  double d = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) d = std::max(d, std::abs(x[k] - y[k]));
  return d;
}

TEST(SimEffects, AeroAndBrakeDragChangeTheCoastDownByTheirForce) {
  const SimRun all = run(kCoastDown + kQuiet);
  for (const char* effect : {"aero_drag", "brake_drag", "rolling_resistance"}) {
    const SimRun off = run(kCoastDown + kQuiet + effect + " = false\n");
    // Initial deceleration difference = the effect's force at 33 m/s / M_eq.
    const double m = truth_value(all, "vehicle.longitudinal_equivalent_mass");
    const double force = std::string(effect) == "aero_drag" ? truth_value(all, "vehicle.aero_coefficient") * 33.0 * 33.0
                         : std::string(effect) == "brake_drag" ? truth_value(all, "vehicle.brake_drag_force")
                                                               : truth_value(all, "vehicle.rolling_resistance_force");
    const double dv = column(off, "vx")[100] - column(all, "vx")[100];  // after 1 s
    EXPECT_NEAR(dv, force / m * 1.0, 0.03 * force / m) << effect;
    EXPECT_EQ(max_difference(all, off, "yaw_rate"), 0.0) << effect;
    EXPECT_EQ(max_difference(all, off, "steer"), 0.0) << effect;
    EXPECT_GT(max_difference(all, off, "vx"), 0.1) << effect;
  }
}

TEST(SimEffects, AntiRollBarsMatterOnlyWhenTheBodyRolls) {
  const std::string straight = "[run]\nduration = 5.0\n[manoeuvre]\ntype = \"straight\"\nspeed = 20.0\ngear = 4\n" + kQuiet;
  EXPECT_EQ(max_difference(run(straight), run(straight + "anti_roll_bars = false\n"), "roll_rate"), 0.0);
  const std::string turn = step_steer(20.0, 0.02, kQuiet);
  const SimRun on = run(turn);
  const SimRun off = run(turn + "anti_roll_bars = false\n");
  const double travel_on = column(on, "susp_travel_fl").back() - column(on, "susp_travel_fr").back();
  const double travel_off = column(off, "susp_travel_fl").back() - column(off, "susp_travel_fr").back();
  EXPECT_GT(std::abs(travel_off), 1.5 * std::abs(travel_on)) << "without bars the body rolls more";
  EXPECT_EQ(truth_value(off, "vehicle.anti_roll_bar_front"), 0.0);
  // The yaw response barely moves (the bars shift load transfer, a second-order effect here).
  EXPECT_LT(std::abs(column(off, "yaw_rate").back() / column(on, "yaw_rate").back() - 1.0), 0.02);
}

TEST(SimEffects, RoadGradeMovesOnlyTheLongitudinalSide) {
  const std::string base = "[run]\nduration = 10.0\n[manoeuvre]\ntype = \"lift_off\"\nspeed = 15.0\ngear = 3\n"
                           "start_time = 4.0\n[road]\ngrade = [[0.0, 0.0], [40.0, 0.06], [120.0, 0.06]]\n" + kQuiet;
  const SimRun on = run(base);
  const SimRun off = run(base + "road_grade = false\n");
  EXPECT_GT(max_difference(on, off, "vx"), 0.5);
  EXPECT_GT(max_difference(on, off, "road_grade"), 0.05);
  EXPECT_EQ(max_difference(on, off, "yaw_rate"), 0.0);
  EXPECT_EQ(max_difference(on, off, "vy"), 0.0);
}

TEST(SimEffects, SensorSwitchesChangeOnlyTheMeasurement) {
  const std::string sc = "[run]\nduration = 4.0\n[manoeuvre]\ntype = \"sine_steer\"\nspeed = 20.0\ngear = 4\n"
                         "start_time = 0.5\namplitude = 0.02\nsweep_time = 3.0\n";
  const SimRun quiet = run(sc + kQuiet);
  const SimRun offsets = run(sc + "[effects]\nsensor_noise = false\nquantization = false\n");
  const SimRun noisy = run(sc + "[effects]\nsensor_offsets = false\nquantization = false\n");
  EXPECT_EQ(quiet.truth, offsets.truth);
  EXPECT_EQ(quiet.truth, noisy.truth);
  // Offsets: exactly the reported constant on every sample of every channel.
  for (std::size_t c = 0; c < quiet.channels.size(); ++c)
    for (std::size_t k = 0; k < quiet.measured.size(); ++k)
      ASSERT_NEAR(offsets.measured[k][c] - quiet.measured[k][c], offsets.offsets[c], 1e-9) << quiet.channels[c].name;
  double spread = 0.0;
  const std::size_t ay = channel_index("ay");
  for (std::size_t k = 0; k < quiet.measured.size(); ++k) spread += std::pow(noisy.measured[k][ay] - quiet.measured[k][ay], 2);
  EXPECT_NEAR(std::sqrt(spread / static_cast<double>(quiet.measured.size())), default_sensor("ay").noise, 0.01);
}

TEST(SimEffects, QuantizationStaysWithinHalfTheDbcResolution) {
  const std::string sc = "[run]\nduration = 3.0\n[manoeuvre]\ntype = \"sine_steer\"\nspeed = 20.0\ngear = 4\n"
                         "start_time = 0.5\namplitude = 0.02\nsweep_time = 2.0\n[effects]\nsensor_noise = false\n"
                         "sensor_offsets = false\n";
  const SimRun fine = run(sc + "quantization = false\n");
  const SimRun coarse = run(sc);
  const CanBus bus(test::testcar_dbc(), can_bindings(fine.scenario.car.vehicle));
  bool any_difference = false;
  for (std::size_t b = 0; b < bus.bindings().size(); ++b) {
    const auto& binding = bus.bindings()[b];
    const auto* sig = test::testcar_dbc().find_message(binding.message)->find_signal(binding.signal);
    const double half = 0.5 * sig->factor / binding.to_dbc * (1 + 1e-9);
    const double d = max_difference(fine, coarse, binding.channel, false);
    EXPECT_LE(d, half) << binding.channel;
    any_difference = any_difference || d > 0.0;
  }
  EXPECT_TRUE(any_difference);
}

// The CAN log decodes back, through the project DBC and decoder, to the channels.
TEST(SimCan, LogDecodesBackToTheChannelsWithinQuantization) {
  const SimRun r = run("[run]\nduration = 3.0\noutput_rate = 1000.0\n[manoeuvre]\ntype = \"sine_steer\"\nspeed = 20.0\n"
                    "gear = 4\nstart_time = 0.2\namplitude = 0.03\nsweep_time = 2.5\n");
  const auto dir = std::filesystem::temp_directory_path() / "dynid_sim_can_test";
  write_run(dir, r);
  const CanBus bus(test::testcar_dbc(), can_bindings(r.scenario.car.vehicle));
  can::CandumpReader reader(dir / "can.log", can::OnError::Stop);
  can::Decoder decoder(test::testcar_dbc());
  std::vector<can::DecodedSignal> out;
  can::Frame f;
  std::size_t checked = 0;
  std::map<std::string, std::size_t> per_message;
  while (reader.next(f)) {
    const auto result = decoder.decode(f, out);
    ASSERT_EQ(result.status, can::DecodeStatus::Ok) << can::explain(f, result);
    ++per_message[result.message->name];
    const auto k = static_cast<std::size_t>(std::lround((f.timestamp - r.scenario.start_timestamp) * 1000.0));
    for (const auto& d : out) {
      for (std::size_t b = 0; b < bus.bindings().size(); ++b) {
        if (bus.bindings()[b].message != result.message->name || bus.bindings()[b].signal != d.signal->name) continue;
        const std::size_t c = bus.channel_of(b);
        const double si = d.value / bus.bindings()[b].to_dbc;
        const double resolution = d.signal->factor / bus.bindings()[b].to_dbc;
        // Exactly the measured (noisy, offset, quantized) channel...
        ASSERT_NEAR(si, r.measured[k][c], 1e-9 * (1 + std::abs(si))) << r.channels[c].name << " at " << k;
        // ...and the true value within the sensor error plus half a step.
        const SensorSpec spec = default_sensor(r.channels[c].name);
        ASSERT_LE(std::abs(si - r.truth[k][c] - r.offsets[c]), 0.5 * resolution + 6 * spec.noise + 1e-9)
            << r.channels[c].name;
        ++checked;
      }
    }
  }
  EXPECT_EQ(reader.error_count(), 0U);
  EXPECT_GT(checked, 10000U);
  EXPECT_EQ(per_message["ESP_Dynamics"], 300U);     // 100 Hz over 3 s
  EXPECT_EQ(per_message["TCU_Status"], 150U);       // 50 Hz
  EXPECT_EQ(per_message["GNSS_RoadPose"], 30U);     // 10 Hz
  std::filesystem::remove_all(dir);
}

TEST(SimScenario, CommittedScenariosRun) {
  for (const auto& entry : std::filesystem::directory_iterator(DYNID_SCENARIO_DIR)) {
    if (entry.path().extension() != ".toml") continue;
    Scenario sc = load_scenario(entry.path());
    const SimRun r = simulate(sc, 1, test::testcar_dbc());
    EXPECT_EQ(r.time.size(), static_cast<std::size_t>(std::lround(sc.duration * sc.output_rate)) + 1) << entry.path();
    for (const auto& row : r.measured)
      for (double x : row) ASSERT_TRUE(std::isfinite(x)) << entry.path();
    // The tare is the standing second before a launch (clutch open): no engagement yet.
    if (sc.manoeuvre.type == ManoeuvreType::Launch && sc.name != "tare") {
      EXPECT_GE(r.statistics.clutch_locks, 3) << "every launch ends with the clutch stuck";
      EXPECT_GT(r.statistics.slipping_time, 2.0);
    }
    // Controlled slip never locks and slips the whole run.
    if (sc.manoeuvre.type == ManoeuvreType::SlipControl) {
      EXPECT_EQ(r.statistics.clutch_locks, 0) << entry.path();
      EXPECT_GT(r.statistics.slipping_time, sc.duration - 0.01) << entry.path();
    }
  }
}

// The actuator follows the swept slip target (within a few rad/s, never near a lock-up) and the
// brakes hold the speed.
TEST(SimPhysics, ControlledSlipFollowsItsSweepAndHoldsTheSpeed) {
  const SimRun r = run(test::load_scenario_text("slip_control.toml") + kQuiet);
  const auto we = test::column(r, "engine_speed");
  const auto wi = test::column(r, "gearbox_input_speed");
  const auto vx = test::column(r, "vx");
  double low = 1e9, high = -1e9;
  for (std::size_t k = 100; k < we.size(); ++k) {
    low = std::min(low, we[k] - wi[k]);
    high = std::max(high, we[k] - wi[k]);
    EXPECT_NEAR(vx[k], r.scenario.manoeuvre.speed, 0.2) << "sample " << k;
  }
  EXPECT_GT(low, 0.5 * r.scenario.manoeuvre.slip_min);
  EXPECT_LT(low, 1.2 * r.scenario.manoeuvre.slip_min);
  EXPECT_GT(high, 0.9 * r.scenario.manoeuvre.slip_max);
  EXPECT_LT(high, 1.2 * r.scenario.manoeuvre.slip_max);
}

TEST(SimScenario, TyposAreRejectedWithTheirPlace) {
  EXPECT_THROW(test::scenario("[effects]\naero_dragg = false\n"), InputError);
  EXPECT_THROW(test::scenario("[vehicle]\nmass = \"heavy\"\n"), InputError);
  EXPECT_THROW(test::scenario("[manoeuvre]\ntype = \"slalom\"\n"), InputError);
  EXPECT_THROW(test::scenario("[road]\ngrade = [[10.0, 0.0], [5.0, 0.1]]\n"), InputError);
  try {
    test::scenario("[run]\noutput_rate = 300.0\n");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("run.output_rate"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dynid::sim
