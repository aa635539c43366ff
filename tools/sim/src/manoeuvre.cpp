#include "dynid/sim/manoeuvre.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>

#include "dynid/error.hpp"

namespace dynid::sim {
namespace {

constexpr std::array<std::pair<const char*, ManoeuvreType>, 9> kTypes{{
    {"straight", ManoeuvreType::Straight},
    {"sine_steer", ManoeuvreType::SineSteer},
    {"step_steer", ManoeuvreType::StepSteer},
    {"spiral", ManoeuvreType::Spiral},
    {"lift_off", ManoeuvreType::LiftOff},
    {"acceleration", ManoeuvreType::Acceleration},
    {"coast_down", ManoeuvreType::CoastDown},
    {"launch", ManoeuvreType::Launch},
    {"slip_control", ManoeuvreType::SlipControl},
}};

// Driver's speed loop, 1/s and 1/s^2 (a calm driver: the speed wanders a little in corners).
constexpr double kSpeedGain = 0.8;
constexpr double kSpeedIntegralGain = 0.15;
// Launch: how hard the driver fights for engine speed while the clutch slips, N m per rad/s.
constexpr double kLaunchEngineGain = 0.6;
constexpr double kLaunchBaseTorque = 40.0;
constexpr double kStandstillSpeed = 0.05;
constexpr double kVariationFrequency = 1.3;  // Hz of the throttle variation
// Controlled slip: the clutch actuator's PI on the slip error, as a clutch torque (N m per
// rad/s, N m per rad): J_e e'' = -Kp e' - Ki e, about 1 Hz and well damped for J_e ~ 0.18.
constexpr double kSlipGain = 1.7;
constexpr double kSlipIntegralGain = 6.5;
// Throttle variation of the controlled slip (Hz): the clamp load follows the engine torque, so
// the rows see several loads at each slip (separates mu from the load scale, borsotto §8.4).
constexpr double kSlipThrottleFrequency = 0.37;

}  // namespace

ManoeuvreType parse_manoeuvre_type(const std::string& name) {
  std::string known;
  for (const auto& [n, t] : kTypes) {
    if (name == n) return t;
    known += known.empty() ? n : std::string(", ") + n;
  }
  throw InputError("manoeuvre type '" + name + "' is unknown (known: " + known + ")");
}

std::string to_string(ManoeuvreType type) {
  for (const auto& [n, t] : kTypes)
    if (t == type) return n;
  return "?";
}

Driver::Driver(const ManoeuvreSpec& spec, const CarModel& model) : spec_(spec), model_(model) {
  gear_ = spec.type == ManoeuvreType::CoastDown ? 0 : spec.type == ManoeuvreType::Launch ? 1 : spec.gear;
  phase_ = spec.type == ManoeuvreType::Launch ? Phase::Wait : Phase::Drive;
}

State Driver::initial_state() const {
  const double speed = spec_.type == ManoeuvreType::Launch ? 0.0 : spec_.speed;
  State s = model_.initial_state(speed, gear_);
  // Controlled slip starts slipping at the lower target (never locked: no stick transition).
  if (spec_.type == ManoeuvreType::SlipControl) s[kWEngine] = s[kWInput] + spec_.slip_min;
  return s;
}

double Driver::steering(double t) const {
  const double tau = t - spec_.start_time;
  if (tau < 0.0) return 0.0;
  switch (spec_.type) {
    case ManoeuvreType::SineSteer: {
      // Swept sine ("sinus vobule"): frequency rising linearly, amplitude optionally falling.
      const double f0 = spec_.frequency_start;
      const double f1 = spec_.frequency_end;
      const double tt = std::min(tau, spec_.sweep_time);
      const double k = (f1 - f0) / spec_.sweep_time;
      const double phase = 2.0 * std::numbers::pi *
                           (f0 * tt + 0.5 * k * tt * tt + f1 * std::max(0.0, tau - spec_.sweep_time));
      const double a_end = spec_.amplitude_end < 0.0 ? spec_.amplitude : spec_.amplitude_end;
      const double a = spec_.amplitude + (a_end - spec_.amplitude) * tt / spec_.sweep_time;
      return a * std::sin(phase);
    }
    case ManoeuvreType::StepSteer:
      return spec_.amplitude * std::min(1.0, tau / spec_.ramp_time);
    case ManoeuvreType::Spiral:
      return std::copysign(std::min(std::abs(spec_.max_steer), spec_.steer_rate * tau), spec_.max_steer);
    default:
      return 0.0;
  }
}

void Driver::hold_speed(double target, const State& s, double step, DriverInputs& in) {
  const auto& v = model_.car.vehicle;
  const double error = target - s[kVx];
  speed_integral_ += error * step;
  const double force = model_.road_load_force(s[kVx]) +
                       v.mass * (kSpeedGain * error + kSpeedIntegralGain * speed_integral_);
  const double alpha = model_.car.driveline.ratio(in.gear);
  if (force >= 0.0 || alpha == 0.0) {
    in.throttle_torque = alpha > 0.0 ? std::max(0.0, force) * v.wheel_radius / alpha : 0.0;
  } else {
    const double per_pa = 2.0 * (v.brake_gain_front + v.brake_gain_rear) / v.wheel_radius;
    in.brake_pressure = -force / per_pa;
  }
}

void Driver::launch(double t, const State& s, DriverInputs& in) {
  const auto& d = model_.car.driveline;
  const double since = t - phase_start_;
  const double engine_hold = kLaunchBaseTorque + kLaunchEngineGain * (spec_.launch_engine_speed - s[kWEngine]);
  in.gear = 1;
  switch (phase_) {
    case Phase::Wait:
      in.clamp_load = 0.0;  // pedal down, revving to the launch speed
      in.brake_pressure = spec_.stop_pressure;
      in.throttle_torque = std::max(0.0, engine_hold);
      if (since >= spec_.wait_time) { phase_ = Phase::Engage; phase_start_ = t; }
      break;
    case Phase::Engage:
      in.clamp_load = d.clutch_max_clamp_load * std::min(1.0, since / spec_.engagement_time);
      in.throttle_torque = std::max(0.0, engine_hold);
      if (since >= spec_.engagement_time) { phase_ = Phase::Drive; phase_start_ = t; }
      break;
    case Phase::Drive:
      in.clamp_load = d.clutch_max_clamp_load;
      in.throttle_torque = spec_.drive_torque *
                           (1.0 + spec_.torque_variation * std::sin(2.0 * std::numbers::pi * kVariationFrequency * since));
      if (s[kWEngine] >= spec_.rev_limit) { phase_ = Phase::Stop; phase_start_ = t; }
      break;
    default:  // Stop: clutch pedal down, brake to a standstill.
      in.clamp_load = 0.0;
      in.brake_pressure = spec_.stop_pressure;
      if (s[kVx] <= kStandstillSpeed) { phase_ = Phase::Wait; phase_start_ = t; }
      break;
  }
}

void Driver::accelerate(double t, const State& s, DriverInputs& in) {
  const auto& d = model_.car.driveline;
  const double half = 0.5 * spec_.shift_time;
  in.throttle_torque = spec_.drive_torque *
                       (1.0 + spec_.torque_variation * std::sin(2.0 * std::numbers::pi * kVariationFrequency * t));
  in.clamp_load = d.clutch_max_clamp_load;
  in.brake_pressure = spec_.drag_pressure * 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * t / spec_.drag_period));
  if (phase_ == Phase::Drive && s[kWEngine] >= spec_.shift_speed && gear_ < d.gear_count()) {
    phase_ = Phase::ShiftOut;
    phase_start_ = t;
  }
  // Measured from the phase just entered: taken before the transition above it was the time
  // since the previous phase began, and the clutch never opened (the gear changed at once).
  const double since = t - phase_start_;
  if (phase_ == Phase::ShiftOut) {
    in.clamp_load = 0.0;
    in.throttle_torque = 0.0;
    if (since >= half) { ++gear_; phase_ = Phase::ShiftIn; phase_start_ = t; }
  } else if (phase_ == Phase::ShiftIn) {
    // The driver lets the clutch in progressively: a short slip phase at every shift.
    in.clamp_load = d.clutch_max_clamp_load * std::min(1.0, since / half);
    in.throttle_torque *= 0.5;
    if (since >= half) phase_ = Phase::Drive;
  }
}

void Driver::slip_control(double t, const State& s, double step, DriverInputs& in) {
  const auto& d = model_.car.driveline;
  const auto& v = model_.car.vehicle;
  in.gear = gear_;
  in.throttle_torque = spec_.drive_torque *
                       (1.0 + spec_.torque_variation * std::sin(2.0 * std::numbers::pi * kSlipThrottleFrequency * t));
  // The actuator: the clutch torque that carries the requested engine torque at the target slip,
  // corrected by a PI on the slip error, turned into a clamp load with the nominal friction of
  // the clutch's data sheet (mu_c + mu_v slip; the PI takes whatever that gets wrong, and the
  // engine's drag the feed-forward ignores).
  const double target = spec_.slip_min + (spec_.slip_max - spec_.slip_min) * 0.5 *
                                             (1.0 - std::cos(2.0 * std::numbers::pi * t / spec_.slip_period));
  const double error = (s[kWEngine] - s[kWInput]) - target;
  slip_integral_ += error * step;
  const double torque = in.throttle_torque + kSlipGain * error + kSlipIntegralGain * slip_integral_;
  const double mu = d.clutch_mu_coulomb + d.clutch_mu_viscous * target;
  in.clamp_load = std::clamp(torque / (d.clutch_radius * mu), 0.0, d.clutch_max_clamp_load);
  // The brakes hold the speed against what the clutch drives (feed-forward + PI on the speed).
  const double speed_error = spec_.speed - s[kVx];
  speed_integral_ += speed_error * step;
  const double drive = std::max(0.0, torque) * d.ratio(gear_) / v.wheel_radius;
  const double wanted = model_.road_load_force(s[kVx]) +
                        v.mass * (kSpeedGain * speed_error + kSpeedIntegralGain * speed_integral_);
  const double per_pa = 2.0 * (v.brake_gain_front + v.brake_gain_rear) / v.wheel_radius;
  in.brake_pressure = std::max(0.0, drive - wanted) / per_pa;
}

DriverInputs Driver::command(double t, const State& s, double step) {
  DriverInputs in;
  in.gear = gear_;
  in.clamp_load = model_.car.driveline.clutch_max_clamp_load;
  in.steer = steering(t);
  switch (spec_.type) {
    case ManoeuvreType::LiftOff:
      in.throttle_torque = t < spec_.start_time ? spec_.drive_torque : 0.0;
      break;
    case ManoeuvreType::CoastDown:
      break;  // neutral, clutch engaged, engine idling
    case ManoeuvreType::Launch:
      launch(t, s, in);
      break;
    case ManoeuvreType::SlipControl:
      slip_control(t, s, step, in);
      break;
    case ManoeuvreType::Acceleration:
      accelerate(t, s, in);
      in.gear = gear_;
      break;
    default:
      hold_speed(spec_.speed, s, step, in);
      break;
  }
  return in;
}

}  // namespace dynid::sim
