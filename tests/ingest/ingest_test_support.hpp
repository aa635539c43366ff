#pragma once
// Test runs for the ingest tests, generated here with known physics (no mock of our parts):
// a car on a flat road at 100 Hz whose speed varies smoothly,
//   wheel_torque = r_w (M dvx + 1/2 rho SCx vx|vx| + F_r)            (longitudinal_wheel)
//   ax           = dvx + offset                                         (kinematic_longitudinal)
//   engine_torque = J dw + p + q w + r w^2, w = engine_speed = G vx / r_w  (locked_driveline)
// plus sensor noise, a gear channel (3, with a short stretch in 2), and gaps: a long one, a
// valid stretch too short to filter, and a gap whose values are garbage (must not matter).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/error.hpp"
#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"

namespace dynid::ingest::test {

struct Truth {
  double mass = 1450.0, scx = 0.72, rolling = 160.0;           // longitudinal
  double scale = 1.0, offset = 0.12;                           // kinematic
  double inertia = 0.9, p = 12.0, q = 0.05, r = 4e-4;          // driveline (gear 3)
  double wheel_radius = 0.31, air_density = 1.2, ratio = 3.9;  // constants
  double vx_noise = 0.01;  // the speed sensor's noise std (m/s): what d_vx's noise grows from
};

struct TestRun {
  RunAnnouncement announcement;
  Eigen::MatrixXd samples;  // grid rows x channels
  std::vector<std::uint8_t> valid;
};

inline RunAnnouncement announcement_for(const Truth& t) {
  RunAnnouncement a;
  a.vehicle = "proto-17";
  a.run = "run-0042";
  a.sample_rate_hz = 100.0;
  a.channels = {{"vx", "m/s"},
                {"ax", "m/s^2"},
                {"wheel_torque", "N m"},
                {"engine_speed", "rad/s"},
                {"engine_torque", "N m"},
                {"gear", "-"}};
  a.models = {{"longitudinal_wheel",
               {{"wheel_radius", t.wheel_radius}, {"air_density", t.air_density}},
               {}},
              {"kinematic_longitudinal", {}, {"dict:lag2:vx"}},
              {"locked_driveline", {{"gear", 3.0}}, {}}};
  a.preprocessing.odmf = 5;  // 8 Hz at 100 Hz
  return a;
}

inline TestRun make_run(Eigen::Index n = 6000, unsigned seed = 1u, const Truth& t = {}) {
  TestRun run{announcement_for(t), Eigen::MatrixXd(n, 6), std::vector<std::uint8_t>(n, 1)};
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / 100.0;
    const double vx =
        18.0 + 6.0 * std::sin(0.21 * s) + 2.5 * std::sin(0.67 * s + 1.0) + 0.8 * std::sin(1.9 * s);
    const double dvx = 6.0 * 0.21 * std::cos(0.21 * s) + 2.5 * 0.67 * std::cos(0.67 * s + 1.0) +
                       0.8 * 1.9 * std::cos(1.9 * s);
    const double force = t.mass * dvx + 0.5 * t.air_density * t.scx * vx * std::abs(vx) + t.rolling;
    const double w = t.ratio * vx / t.wheel_radius;
    const double dw = t.ratio * dvx / t.wheel_radius;
    const bool second = k >= 4100 && k < 4400;
    run.samples(k, 0) = vx + t.vx_noise * noise(rng);
    run.samples(k, 1) = t.scale * dvx + t.offset + 0.05 * noise(rng);
    run.samples(k, 2) = t.wheel_radius * force + 5.0 * noise(rng);
    run.samples(k, 3) = w + 0.05 * noise(rng);
    run.samples(k, 4) = t.inertia * dw + t.p + t.q * w + t.r * w * w + 0.5 * noise(rng);
    run.samples(k, 5) = second ? 2.0 : 3.0;
  }
  const auto gap = [&](Eigen::Index first, Eigen::Index count, double value) {
    for (Eigen::Index k = first; k < std::min(n, first + count); ++k) {
      run.valid[static_cast<std::size_t>(k)] = 0;
      run.samples.row(k).setConstant(value);
    }
  };
  gap(1500, 40, 0.0);    // a gap
  gap(1550, 10, 0.0);    // after a 10-sample valid stretch: too short to filter
  gap(3000, 25, 1.0e9);  // garbage in a gap must not matter
  return run;
}

/// A run whose model reads far around each row: clutch_slip with a stick margin of 0.4 s (40
/// samples, more than RunProcessor's least context). Cycles of 5 s: an engagement (clamp load
/// ramps up, the slip falls linearly to 0), 2 s locked (the torque there is not the friction
/// law: the mask must leave those rows and the 0.4 s around them out), then the clutch opens
/// (slip jumps, load 0). Noisy channels, a gap; odmf 7 (rows on every 7th grid sample).
inline TestRun make_clutch_run(Eigen::Index n = 6000, unsigned seed = 3u) {
  RunAnnouncement a;
  a.vehicle = "proto-17";
  a.run = "launch-0007";
  a.sample_rate_hz = 100.0;
  a.channels = {{"engine_speed", "rad/s"},
                {"engine_torque", "N m"},
                {"gearbox_input_speed", "rad/s"},
                {"clutch_clamp_load", "N"}};
  a.models = {{"clutch_slip",
               {{"clutch_friction_radius", 0.11},
                {"min_slip_speed", 2.0},
                {"stick_margin", 0.4},
                {"open_clamp_load", 150.0}},
               {"viscous_friction", "engine_torque_offset"}}};
  a.preprocessing.odmf = 7;
  TestRun run{a, Eigen::MatrixXd(n, 4), std::vector<std::uint8_t>(n, 1)};
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const double inertia = 0.18, radius = 0.11, mu_c = 0.16, mu_v = 0.004, pi = 3.141592653589793;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / 100.0;
    const double tau = std::fmod(t, 5.0);
    const double we = 220.0 + 40.0 * std::sin(2.0 * pi * 0.3 * t);
    const double dwe = 40.0 * 2.0 * pi * 0.3 * std::cos(2.0 * pi * 0.3 * t);
    double slip = 0.0, load = 0.0, torque = 0.0;
    if (tau < 1.5) {  // engaging
      slip = 150.0 * (1.0 - tau / 1.5);
      load = 4000.0 * tau / 1.5;
      torque = inertia * dwe + radius * load * (mu_c + mu_v * slip);
    } else if (tau < 3.5) {  // locked: the engine drives the car, not the friction law
      load = 8000.0;
      torque = 60.0 + 10.0 * std::sin(2.0 * pi * 1.1 * t);
    } else {  // open
      slip = 20.0 + 30.0 * (tau - 3.5);
      torque = inertia * dwe;
    }
    run.samples(k, 0) = we + 0.3 * noise(rng);
    run.samples(k, 1) = torque + 1.0 * noise(rng);
    run.samples(k, 2) = we - slip + 0.3 * noise(rng);
    run.samples(k, 3) = load + 20.0 * noise(rng);
  }
  for (Eigen::Index k = 2210; k < std::min(n, Eigen::Index{2260}); ++k) run.valid[static_cast<std::size_t>(k)] = 0;
  return run;
}

/// Cuts [first, first + count) of the run into a sealed chunk.
inline Chunk cut(const TestRun& run, std::uint64_t sequence, Eigen::Index first,
                 Eigen::Index count) {
  if (first < 0 || count < 1 || first + count > run.samples.rows())
    throw std::out_of_range("cut: rows [" + std::to_string(first) + ", " +
                            std::to_string(first + count) + ") outside a run of " +
                            std::to_string(run.samples.rows()) + " samples");
  Chunk c;
  c.vehicle = run.announcement.vehicle;
  c.run = run.announcement.run;
  c.sequence = sequence;
  c.first_sample_index = static_cast<std::uint64_t>(first);
  c.samples = run.samples.middleRows(first, count);
  c.valid.assign(run.valid.begin() + first, run.valid.begin() + first + count);
  c.seal();
  return c;
}

/// Chunk boundaries: random sizes in [1, largest], covering the run.
inline std::vector<Eigen::Index> random_cuts(Eigen::Index n, Eigen::Index largest, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Eigen::Index> size(1, largest);
  std::vector<Eigen::Index> sizes;
  for (Eigen::Index done = 0; done < n;) {
    sizes.push_back(std::min(size(rng), n - done));
    done += sizes.back();
  }
  return sizes;
}

template <class Call>
void expect_input_error(Call call, const std::vector<std::string>& words) {
  try {
    call();
    ADD_FAILURE() << "accepted; expected an InputError";
  } catch (const InputError& e) {
    for (const std::string& w : words)
      EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what() << " lacks " << w;
  }
}

}  // namespace dynid::ingest::test
