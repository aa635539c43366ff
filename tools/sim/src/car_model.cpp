#include "dynid/sim/car_model.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/sim/clutch.hpp"
#include "dynid/sim/tyre.hpp"

namespace dynid::sim {
namespace {

// Below this speed the slip angle uses this speed in its denominator: a standing car has no
// defined slip angle, and the tyre then acts as a stiff lateral damper (a relaxation-length
// model would do the same job with one more state per tyre).
constexpr double kSlipSpeedFloor = 1.0;
// Speeds that smooth sign() for resistances that oppose the motion, m/s and rad/s.
constexpr double kRollingSignSpeed = 0.1;
constexpr double kBrakeSignSpeed = 0.05;
constexpr double kEngineSignSpeed = 1.0;
// A rigid shaft is approximated by this stiffness multiple (see effects.hpp).
constexpr double kRigidShaftFactor = 30.0;

struct Corner {
  double travel = 0.0;
  double rate = 0.0;
};

std::array<Corner, kCorners> corner_motion(const VehicleParameters& v, const State& s) {
  std::array<Corner, kCorners> c{};
  for (int i = 0; i < kCorners; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double zb = s[kZ] + v.corner_y(i) * s[kPhi] - v.corner_x(i) * s[kTheta];
    const double dzb = s[kDz] + v.corner_y(i) * s[kDphi] - v.corner_x(i) * s[kDtheta];
    c[k].travel = s[kZu0 + k] - zb;  // compression when the wheel rises towards the body
    c[k].rate = s[kDzu0 + k] - dzb;
  }
  return c;
}

// Suspension force on the body (spring, dampers, friction, anti-roll bar), N.
void suspension_forces(const VehicleParameters& v, const Effects& fx, Evaluation& e) {
  for (int i = 0; i < kCorners; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const bool front = i < 2;
    const double t = e.travel[k];
    const double rate = e.travel_rate[k];
    double f = v.static_spring_force(i) + (front ? v.spring_front : v.spring_rear) * t +
               (front ? v.damping_front : v.damping_rear) * rate;
    if (fx.nonlinear_damping)
      f += (front ? v.damping_quadratic_front : v.damping_quadratic_rear) * std::abs(rate) * rate;
    if (fx.suspension_friction)
      f += v.suspension_friction * std::tanh(rate / v.suspension_friction_speed);
    if (fx.anti_roll_bars) {
      // Venture's bar: F_i = k_bar (s_i - s_opposite) on each wheel of the axle.
      const std::size_t other = k ^ 1U;
      f += (front ? v.arb_front : v.arb_rear) * (t - e.travel[other]);
    }
    e.suspension_force[k] = f;
  }
}

void tyre_loads(const VehicleParameters& v, const Effects& fx, const State& s, Evaluation& e) {
  const double kt = v.tyre_vertical_stiffness;
  for (int i = 0; i < kCorners; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double fz0 = v.static_tyre_load(i);
    double fz = 0.0;
    if (fx.tyre_vertical_compliance)
      fz = fz0 - kt * s[kZu0 + k];  // flat road: the road surface is at the static position
    else
      fz = e.suspension_force[k] - v.unsprung_mass(i) * e.gravity[2];
    e.tyre_load[k] = std::max(0.0, fz);
    e.tyre_deflection[k] = e.tyre_load[k] / kt;
  }
}

// Tyre forces in the yaw frame; `shaft_torque` drives the front wheels.
void tyre_forces(const VehicleParameters& v, const Effects& fx, const State& s,
                 const DriverInputs& in, double shaft_torque, Evaluation& e) {
  for (int i = 0; i < kCorners; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const bool front = i < 2;
    const double fz = fx.load_transfer ? e.tyre_load[k] : v.static_tyre_load(i);
    const double delta = front ? in.steer : 0.0;
    const double cx = s[kVx] - s[kR] * v.corner_y(i);
    const double cy = s[kVy] + s[kR] * v.corner_x(i);
    const double cd = std::cos(delta);
    const double sd = std::sin(delta);
    const double wx = cx * cd + cy * sd;  // contact velocity in the wheel frame
    const double wy = -cx * sd + cy * cd;
    e.wheel_speed[k] = wx;

    const double r = v.wheel_radius;
    double brake = (front ? v.brake_gain_front : v.brake_gain_rear) * in.brake_pressure;
    if (fx.brake_drag) brake += v.brake_drag_torque;
    double fxw = (front ? 0.5 * shaft_torque : 0.0) / r - brake / r * std::tanh(wx / kBrakeSignSpeed);
    if (fx.rolling_resistance)
      fxw -= v.rolling_resistance * fz * std::tanh(wx / kRollingSignSpeed);

    const double alpha = -std::atan2(wy, std::max(std::abs(wx), kSlipSpeedFloor));
    const double c0 = front ? v.cornering_stiffness_front : v.cornering_stiffness_rear;
    const double c = fx.tyre_load_sensitivity
                         ? cornering_stiffness_at_load(c0, fz, v.static_tyre_load(i),
                                                       v.tyre_load_sensitivity)
                         : c0;
    // Friction circle: what longitudinal force uses is not available laterally.
    const double mu_fz = v.tyre_friction * fz;
    const double lateral_limit = std::sqrt(std::max(mu_fz * mu_fz - fxw * fxw, 0.01 * mu_fz * mu_fz));
    const double fyw = lateral_force(alpha, c, lateral_limit, fx.tyre_saturation);
    e.tyre_fx[k] = fxw * cd - fyw * sd;
    e.tyre_fy[k] = fxw * sd + fyw * cd;
  }
}

// Engine net torque: driver request plus idle governor, limited, minus friction.
double engine_torque(const DrivelineParameters& d, double w_engine, double request) {
  const double governor = std::max(0.0, d.idle_governor_gain * (d.engine_idle_speed - w_engine));
  const double produced = std::clamp(request + governor, 0.0, d.engine_max_torque);
  const double drag =
      d.engine_drag_constant * std::tanh(w_engine / kEngineSignSpeed) + d.engine_drag_viscous * w_engine;
  return produced - drag;
}

void driveline(const CarModel& m, const State& s, const DriverInputs& in, const Mode& mode,
               Evaluation& e) {
  const auto& d = m.car.driveline;
  State& ds = e.derivative;
  const double alpha = d.ratio(in.gear);
  const double w_wheel = s[kVx] / m.car.vehicle.wheel_radius;
  double load_on_input = 0.0;
  if (in.gear > 0) {
    const double twist_rate = s[kWInput] / alpha - w_wheel;
    e.shaft_torque = m.shaft_stiffness() * s[kShaftTwist] + m.shaft_damping() * twist_rate;
    ds[kShaftTwist] = twist_rate;
    load_on_input = e.shaft_torque / alpha;
  } else {
    // Neutral: nothing holds the differential side, the twist relaxes.
    e.shaft_torque = 0.0;
    ds[kShaftTwist] = -20.0 * s[kShaftTwist];
    load_on_input = d.gearbox_drag * std::tanh(s[kWInput] / kEngineSignSpeed);
  }
  const double j_in = in.gear > 0 ? d.input_side_inertia(in.gear) : d.gearbox_input_inertia;
  e.engine_torque = engine_torque(d, s[kWEngine], in.throttle_torque);
  const double locked_accel = (e.engine_torque - load_on_input) / (d.engine_inertia + j_in);
  e.locked_clutch_torque = e.engine_torque - d.engine_inertia * locked_accel;
  if (mode.clutch_locked) {
    e.clutch_torque = e.locked_clutch_torque;
    ds[kWEngine] = locked_accel;
    ds[kWInput] = locked_accel;
  } else {
    const auto friction = ClutchFriction::from(d, m.effects.clutch_stribeck, m.effects.clutch_viscous);
    e.clutch_torque = friction.torque(s[kWEngine] - s[kWInput], in.clamp_load);
    ds[kWEngine] = (e.engine_torque - e.clutch_torque) / d.engine_inertia;
    ds[kWInput] = (e.clutch_torque - load_on_input) / j_in;
  }
}

// Solves [a b; b c] [u; w] = [p; q].
std::array<double, 2> solve2(double a, double b, double c, double p, double q) {
  const double det = a * c - b * b;
  return {(p * c - b * q) / det, (a * q - b * p) / det};
}

void body_and_planar(const VehicleParameters& v, const Effects& fx, const State& s, Evaluation& e) {
  State& ds = e.derivative;
  const double ms = v.sprung_mass();
  const double h = v.cg_height;
  const double gx = e.gravity[0];
  const double gy = e.gravity[1];
  const double gz = e.gravity[2];
  const double vx = s[kVx];
  const double air_speed = vx + v.head_wind;
  e.aero_drag = fx.aero_drag ? 0.5 * v.air_density * v.scx * air_speed * std::abs(air_speed) : 0.0;

  double sum_fx = 0.0, sum_fy = 0.0, yaw_moment = 0.0;
  double heave = 0.0, roll = 0.0, pitch = 0.0;
  for (int i = 0; i < kCorners; ++i) {
    const auto k = static_cast<std::size_t>(i);
    sum_fx += e.tyre_fx[k];
    sum_fy += e.tyre_fy[k];
    yaw_moment += v.corner_x(i) * e.tyre_fy[k] - v.corner_y(i) * e.tyre_fx[k];
    // The static part balances the sprung weight wherever the sprung CG is exactly.
    const double df = e.suspension_force[k] - v.static_spring_force(i);
    heave += df;
    roll += v.corner_y(i) * df;
    pitch -= v.corner_x(i) * df;
    const double mu = v.unsprung_mass(i);
    ds[kZu0 + k] = fx.tyre_vertical_compliance ? s[kDzu0 + k] : 0.0;
    ds[kDzu0 + k] = fx.tyre_vertical_compliance
                        ? (e.tyre_load[k] - e.suspension_force[k] + mu * gz) / mu
                        : 0.0;
  }
  const double g_normal = -gz;
  const double m = v.mass;
  const auto lat = solve2(m, -ms * h, v.roll_inertia + ms * h * h, sum_fy + m * gy,
                          roll + ms * g_normal * h * s[kPhi] - ms * h * gy);
  const auto lon = solve2(v.longitudinal_equivalent_mass(), ms * h, v.pitch_inertia + ms * h * h,
                          sum_fx + m * gx - e.aero_drag,
                          pitch + ms * g_normal * h * s[kTheta] + ms * h * gx -
                              v.aero_height * e.aero_drag);
  const double r = s[kR];
  ds[kVx] = lon[0] + r * s[kVy];
  ds[kVy] = lat[0] - r * vx;
  ds[kR] = yaw_moment / v.yaw_inertia;
  ds[kDphi] = lat[1];
  ds[kDtheta] = lon[1];
  ds[kDz] = (heave + ms * (gz + kGravity)) / ms;
  ds[kZ] = s[kDz];
  ds[kPhi] = s[kDphi];
  ds[kTheta] = s[kDtheta];
  const double c = std::cos(s[kPsi]);
  const double sn = std::sin(s[kPsi]);
  ds[kX] = vx * c - s[kVy] * sn;
  ds[kY] = vx * sn + s[kVy] * c;
  ds[kPsi] = r;
  ds[kDistance] = vx;
}

}  // namespace

Evaluation CarModel::evaluate(const State& s, const DriverInputs& in, const Mode& mode) const {
  const auto& v = car.vehicle;
  Evaluation e;
  e.grade = effects.road_grade ? road.grade.at(s[kDistance]) : 0.0;
  e.bank = effects.road_bank ? road.bank.at(s[kDistance]) : 0.0;
  e.gravity = gravity_in_road_frame(e.grade, e.bank);
  const auto corners = corner_motion(v, s);
  for (std::size_t k = 0; k < kCorners; ++k) {
    e.travel[k] = corners[k].travel;
    e.travel_rate[k] = corners[k].rate;
  }
  suspension_forces(v, effects, e);
  tyre_loads(v, effects, s, e);
  driveline(*this, s, in, mode, e);
  tyre_forces(v, effects, s, in, e.shaft_torque, e);
  body_and_planar(v, effects, s, e);
  return e;
}

double CarModel::shaft_stiffness() const {
  const double k = 2.0 * car.driveline.driveshaft_stiffness;
  return effects.driveshaft_compliance ? k : kRigidShaftFactor * k;
}

double CarModel::shaft_damping() const {
  const double b = 2.0 * car.driveline.driveshaft_damping;
  return effects.driveshaft_compliance ? b : std::sqrt(kRigidShaftFactor) * b;
}

double CarModel::road_load_force(double speed) const {
  const auto& v = car.vehicle;
  double f = 0.0;
  if (effects.rolling_resistance) f += v.rolling_resistance * v.mass * kGravity;
  if (effects.aero_drag) f += 0.5 * v.air_density * v.scx * (speed + v.head_wind) * std::abs(speed + v.head_wind);
  if (effects.brake_drag) f += 4.0 * v.brake_drag_torque / v.wheel_radius;
  return f;
}

State CarModel::initial_state(double speed, int gear) const {
  State s{};
  s[kVx] = speed;
  const auto& d = car.driveline;
  const double idle = d.engine_idle_speed;
  if (gear == 0) {
    s[kWEngine] = idle;  // clutch pedal released: engine and input shaft idle together
    s[kWInput] = idle;
    return s;
  }
  s[kWInput] = d.ratio(gear) * speed / car.vehicle.wheel_radius;
  // Fast enough to drive with the clutch engaged, or a standing start with the pedal down.
  s[kWEngine] = s[kWInput] >= idle ? s[kWInput] : idle;
  if (speed > 0.0)
    s[kShaftTwist] = road_load_force(speed) * car.vehicle.wheel_radius / shaft_stiffness();
  return s;
}

}  // namespace dynid::sim
