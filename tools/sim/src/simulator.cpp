#include "dynid/sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "dynid/error.hpp"
#include "dynid/sim/can_bus.hpp"
#include "dynid/sim/clutch.hpp"
#include "dynid/sim/sensors.hpp"

namespace dynid::sim {
namespace {

// Slip speeds below this count as a zero crossing (rad/s).
constexpr double kLockSlip = 1e-3;
// After unlocking, the slip starts this far from zero in the direction the torque drives it, so
// the friction law sees which way the clutch slides (mu(0) = 0).
constexpr double kUnlockSlip = 1e-6;

State add_scaled(const State& s, const State& d, double h) {
  State out;
  for (std::size_t i = 0; i < kStateSize; ++i) out[i] = s[i] + h * d[i];
  return out;
}

ClutchFriction friction_of(const CarModel& m) {
  return ClutchFriction::from(m.car.driveline, m.effects.clutch_stribeck, m.effects.clutch_viscous);
}

// The driver changed gear: the synchronizer matches the input shaft to the wheels.
void change_gear(const CarModel& m, int gear, State& s, Mode& mode) {
  if (gear > 0) s[kWInput] = m.car.driveline.ratio(gear) * s[kVx] / m.car.vehicle.wheel_radius;
  mode.clutch_locked = false;
}

// Stick/slip transitions between steps (see simulator.hpp).
void update_clutch(const CarModel& m, const DriverInputs& in, double slip_before, State& s, Mode& mode,
                   RunStatistics& stats) {
  const auto friction = friction_of(m);
  const auto& d = m.car.driveline;
  const double capacity = friction.static_capacity(in.clamp_load);
  const Evaluation e = m.evaluate(s, in, Mode{true});
  if (mode.clutch_locked) {
    if (std::abs(e.locked_clutch_torque) > capacity) {
      mode.clutch_locked = false;
      ++stats.clutch_unlocks;
      // Torque above capacity: the engine side runs ahead when it drives, behind when it brakes.
      s[kWEngine] += std::copysign(kUnlockSlip, e.locked_clutch_torque);
    }
    return;
  }
  const double slip = s[kWEngine] - s[kWInput];
  const bool crossed = slip == 0.0 || (slip > 0.0) != (slip_before > 0.0) || std::abs(slip) < kLockSlip;
  if (!crossed || in.clamp_load <= 0.0 || std::abs(e.locked_clutch_torque) > capacity) return;
  const double j_in = in.gear > 0 ? d.input_side_inertia(in.gear) : d.gearbox_input_inertia;
  // Momentum is conserved when the two sides stick together.
  const double w = (d.engine_inertia * s[kWEngine] + j_in * s[kWInput]) / (d.engine_inertia + j_in);
  s[kWEngine] = w;
  s[kWInput] = w;
  mode.clutch_locked = true;
  ++stats.clutch_locks;
}

// Near a stick (small slip, or a slip that would cross zero within the step) the slipping
// clutch is stiff: the Stribeck slope over the small input-side inertia has time constants far
// below the step, and a crossing inside an RK4 step chatters. There the step is cut into
// kFineSubsteps pieces and stick/slip is checked after each.
constexpr double kFineSlip = 2.0;  // rad/s
constexpr int kFineSubsteps = 20;

void advance(const CarModel& m, const DriverInputs& in, double h, State& s, Mode& mode, RunStatistics& stats) {
  int substeps = 1;
  if (!mode.clutch_locked && in.clamp_load > 0.0) {
    const double slip = s[kWEngine] - s[kWInput];
    const State d = m.evaluate(s, in, mode).derivative;
    const double predicted = slip + h * (d[kWEngine] - d[kWInput]);
    if (std::abs(slip) < kFineSlip || (predicted > 0.0) != (slip > 0.0)) substeps = kFineSubsteps;
    stats.slipping_time += h;
  }
  const double dt = h / substeps;
  for (int i = 0; i < substeps; ++i) {
    const double slip_before = s[kWEngine] - s[kWInput];
    s = rk4_step(m, s, in, mode, dt);
    update_clutch(m, in, slip_before, s, mode, stats);
  }
}

long steps_of(double period, double h) { return std::lround(period / h); }

class Recorder {
 public:
  Recorder(const Scenario& sc, std::uint64_t seed, const can::Database& dbc)
      : bus_(dbc, can_bindings(sc.car.vehicle)),
        sensors_(seed, sc.effects, sc.noise_scale, sc.sensor_gains),
        quantize_(sc.effects.quantization),
        iface_(sc.interface_name),
        t0_(sc.start_timestamp),
        held_(channel_catalogue().size(), 0.0),
        counters_(bus_.schedule().size(), 0) {
    const double h = 1.0 / sc.internal_rate;
    for (const auto& sm : bus_.schedule()) {
      const long period = steps_of(sm.period, h);
      if (period <= 0 || std::abs(static_cast<double>(period) * h - sm.period) > 1e-9)
        throw InputError("CAN message " + sm.message->name + ": its period is not a multiple of the step");
      periods_.push_back(period);
      phases_.push_back(steps_of(sm.phase, h));
    }
    output_every_ = std::lround(sc.internal_rate / sc.output_rate);
  }

  bool due(long step) const {
    if (step % output_every_ == 0) return true;
    for (std::size_t i = 0; i < periods_.size(); ++i)
      if (step >= phases_[i] && (step - phases_[i]) % periods_[i] == 0) return true;
    return false;
  }

  void record(long step, double t, const std::vector<double>& truth, Run& run) {
    // Before a channel's first message the receiver has its power-on reading, not a zero.
    if (step == 0)
      for (std::size_t c = 0; c < held_.size(); ++c) {
        const auto b = bus_.binding_of_channel(c);
        const double value = sensors_.measure(c, truth[c]);
        held_[c] = b && quantize_ ? bus_.quantize(*b, value) : value;
      }
    for (std::size_t i = 0; i < periods_.size(); ++i) {
      if (step < phases_[i] || (step - phases_[i]) % periods_[i] != 0) continue;
      sample_message(i, t, truth, run);
    }
    if (step % output_every_ != 0) return;
    // Channels no message carries are sampled on the output grid.
    for (std::size_t c = 0; c < held_.size(); ++c)
      if (!bus_.binding_of_channel(c)) held_[c] = sensors_.measure(c, truth[c]);
    run.time.push_back(t);
    run.truth.push_back(truth);
    run.measured.push_back(held_);
  }

  const std::vector<double>& offsets() const { return sensors_.offsets(); }

 private:
  void sample_message(std::size_t i, double t, const std::vector<double>& truth, Run& run) {
    const auto& sm = bus_.schedule()[i];
    for (std::size_t b : sm.bindings) {
      const std::size_t c = bus_.channel_of(b);
      const double value = sensors_.measure(c, truth[c]);
      held_[c] = quantize_ ? bus_.quantize(b, value) : value;
    }
    run.frames.push_back(bus_.encode(i, held_, t0_ + t, iface_, counters_[i]++));
  }

  CanBus bus_;
  SensorBank sensors_;
  bool quantize_;
  std::string iface_;
  double t0_;
  std::vector<double> held_;
  std::vector<std::uint32_t> counters_;
  std::vector<long> periods_;
  std::vector<long> phases_;
  long output_every_ = 1;
};

}  // namespace

State rk4_step(const CarModel& m, const State& s, const DriverInputs& in, const Mode& mode, double h) {
  const State k1 = m.evaluate(s, in, mode).derivative;
  const State k2 = m.evaluate(add_scaled(s, k1, 0.5 * h), in, mode).derivative;
  const State k3 = m.evaluate(add_scaled(s, k2, 0.5 * h), in, mode).derivative;
  const State k4 = m.evaluate(add_scaled(s, k3, h), in, mode).derivative;
  State out;
  for (std::size_t i = 0; i < kStateSize; ++i)
    out[i] = s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  return out;
}

Run simulate(const Scenario& sc, std::uint64_t seed, const can::Database& dbc) {
  const CarModel model{sc.car, sc.effects, sc.road};
  Driver driver(sc.manoeuvre, model);
  Recorder recorder(sc, seed, dbc);
  Run run;
  run.scenario = sc;
  run.seed = seed;
  run.channels = channel_catalogue();
  run.offsets = recorder.offsets();

  const double h = 1.0 / sc.internal_rate;
  const long steps = std::lround(sc.duration * sc.internal_rate);
  State s = driver.initial_state();
  Mode mode;
  mode.clutch_locked = s[kWEngine] == s[kWInput];
  std::optional<int> gear;
  for (long k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * h;
    const DriverInputs in = driver.command(t, s, h);
    if (gear && *gear != in.gear) change_gear(model, in.gear, s, mode);
    gear = in.gear;
    if (recorder.due(k)) {
      const Evaluation e = model.evaluate(s, in, mode);
      const auto truth = true_channel_values(model, s, in, e);
      run.statistics.max_lateral_slip = std::max(run.statistics.max_lateral_slip, std::abs(truth[channel_index("ay")]));
      recorder.record(k, t, truth, run);
    }
    if (k == steps) break;
    advance(model, in, h, s, mode, run.statistics);
  }
  return run;
}

}  // namespace dynid::sim
