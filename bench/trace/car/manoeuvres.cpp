#include "manoeuvres.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

namespace dynid::benchcar {
namespace {

constexpr double kDt = 1e-3;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kLockedClampLoad = CarParameters{}.clutch_full_load;  // N
constexpr double kUpshiftSpeed = 377.0;      // rad/s (3600 rpm)
constexpr double kShiftTime = 0.35;          // s with the clutch open
constexpr double kTorqueCutTime = 0.15;      // s of torque ramp-down before a shift
constexpr double kLockSlip = 0.3;            // rad/s: the launch's slip controller closes here
constexpr double kClampApplyRate = 20000.0;  // N/s: the actuator closes the clutch in ~0.45 s
constexpr double kClampReleaseRate = 60000.0;  // N/s: and opens it in 0.15 s
// The clutch actuator's travel (CarParameters::clutch_engagement) is linear in the load (a
// linear-rate spring, so that the curve of clutch_torque_curve, piecewise linear, has an exact
// truth at its knots). Open, the actuator waits at the touch point, as an automated clutch's
// does: a travel jumping from 0 to the touch point at a launch would be smeared by the low-pass
// into the launch's first rows.
// A launch's clutch torque, N m, and the factors of successive launches: a driver's launches
// differ, and only launches that differ tell the clutch's slip-proportional friction from its
// engagement curve (clutch_torque_curve.hpp).
constexpr double kLaunchTorque = 230.0;
constexpr std::array<double, 5> kLaunchTorqueFactors{1.0, 0.8, 1.2, 0.9, 1.1};

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

double grade_at(const Perturbation& p, double distance) {
  if (p.grade.empty()) return 0.0;
  if (distance <= p.grade.front().first) return p.grade.front().second;
  for (std::size_t i = 1; i < p.grade.size(); ++i)
    if (distance <= p.grade[i].first) {
      const auto& [x0, g0] = p.grade[i - 1];
      const auto& [x1, g1] = p.grade[i];
      return g0 + (g1 - g0) * (distance - x0) / (x1 - x0);
    }
  return p.grade.back().second;
}

// The pressure of a foot resting on the brake pedal: it varies (0.4 .. 1.6 times the mean, at
// 0.15 Hz), so that the drag is no constant force (which rolling resistance would absorb).
double drag_pressure(const Perturbation& p, double t) {
  return p.brake_drag_pressure * (1.0 + 0.6 * std::sin(kTwoPi * 0.15 * t + 1.0));
}

// A gust: four sines between 0.3 and 1.5 Hz with phases drawn from the seed.
struct Gust {
  std::array<double, 4> frequency{};
  std::array<double, 4> phase{};
  double amplitude = 0.0;
  Gust(double amp, std::uint64_t seed) : amplitude(amp) {
    std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
    std::uniform_real_distribution<double> f(0.3, 1.5), ph(0.0, kTwoPi);
    for (std::size_t i = 0; i < 4; ++i) {
      frequency[i] = f(rng);
      phase[i] = ph(rng);
    }
  }
  double at(double t) const {
    double w = 0.0;
    for (std::size_t i = 0; i < 4; ++i) w += std::sin(kTwoPi * frequency[i] * t + phase[i]);
    return amplitude * w;
  }
};

// Road load and external forces on the longitudinal axis at speed v (>= 0), distance x.
struct RoadLoad {
  const CarParameters& car;
  const Perturbation& p;
  Gust gust;
  double operator()(double t, double v, double x, double mass, bool brake_drag) const {
    const double air = v + p.head_wind + gust.at(t);
    const double drag = 0.5 * car.air_density * car.scx * air * std::abs(air);
    const double rolling = car.rolling_resistance * std::tanh(v / 0.05);
    const double slope = mass * car.gravity * std::sin(grade_at(p, x));
    const double brake = brake_drag ? car.brake_gain * drag_pressure(p, t) * std::tanh(v / 0.05) : 0.0;
    return drag + rolling + slope + brake;
  }
};

// Every channel the sensors measure, one sample.
struct Sample {
  double vx = 0, vy = 0, yaw_rate = 0, ax = 0, ay = 0, az = 0, steer = 0;
  double engine_speed = 0, engine_torque = 0, input_speed = 0, gear = 0, gear_ratio = 0;
  double clamp_load = 0, wheel_torque = 0, brake_pressure = 0;
};

Truth make_truth(const std::vector<double>& time, const std::vector<Sample>& s) {
  Truth t;
  t.time = time;
  auto put = [&](const char* name, double Sample::*field) {
    std::vector<double>& v = t[name];
    v.reserve(s.size());
    for (const Sample& x : s) v.push_back(x.*field);
  };
  put("vx", &Sample::vx);
  put("vy", &Sample::vy);
  put("yaw_rate", &Sample::yaw_rate);
  put("ax", &Sample::ax);
  put("ay", &Sample::ay);
  put("az", &Sample::az);
  put("steer", &Sample::steer);
  put("engine_speed", &Sample::engine_speed);
  put("engine_torque", &Sample::engine_torque);
  put("gearbox_input_speed", &Sample::input_speed);
  put("gear", &Sample::gear);
  put("gear_ratio", &Sample::gear_ratio);
  put("clutch_clamp_load", &Sample::clamp_load);
  std::vector<double>& travel = t["clutch_engagement"];
  for (const Sample& x : s) travel.push_back(CarParameters{}.clutch_engagement(x.clamp_load));
  put("wheel_torque", &Sample::wheel_torque);
  put("brake_pressure", &Sample::brake_pressure);
  return t;
}

// The clutch's friction coefficient at slip dw (> 0) after `energy` J dissipated.
double clutch_mu(const CarParameters& car, const Perturbation& p, double dw, double energy) {
  double mu = car.clutch_mu_coulomb * (1.0 - p.clutch_fade * energy / 1e5) + car.clutch_mu_viscous * dw;
  if (p.stribeck_speed > 0.0) mu += p.stribeck_rise * std::exp(-(dw / p.stribeck_speed) * (dw / p.stribeck_speed));
  return mu;
}

// The longitudinal driveline: a state machine over locked / shifting / open (neutral, braking,
// standing) / launching, integrated with RK4 within each mode.
class Driveline {
 public:
  enum class Mode { kLocked, kShift, kOpen, kLaunch };

  Driveline(const CarParameters& car, const Perturbation& p, double v0, int gear)
      : car_(car), p_(p), load_{car, p, Gust(p.gust_amplitude, p.seed)}, mass_(car.mass), v_(v0), gear_(gear) {
    mode_ = gear > 0 ? Mode::kLocked : Mode::kOpen;
    we_ = gear > 0 ? car.gear_ratio(gear) * v0 / car.wheel_radius : car.idle_speed;
    clamp_ = gear > 0 ? kLockedClampLoad : 0.0;
  }

  /// One step of kDt at time t with the driver's torque target and brake pressure (Pa); the
  /// clutch is opened and the gear put in neutral while braking.
  Sample step(double t, double torque_target, double brake_pa, bool launch_request) {
    Sample s;
    if (brake_pa > 0.0 && mode_ != Mode::kOpen) {
      mode_ = Mode::kOpen;
      input_ = car_.gear_ratio(gear_) * v_ / car_.wheel_radius;
      gear_ = 0;
      open_since_ = t;
    }
    if (mode_ == Mode::kOpen && launch_request && brake_pa <= 0.0 && v_ < 0.5) start_launch(t);
    const double r = car_.wheel_radius;
    const double eta = car_.efficiency;
    const bool drag = brake_pa <= 0.0;
    switch (mode_) {
      case Mode::kLocked: {
        // A reversal of the engine torque's sign starts the lash (backlash family).
        if (p_.backlash_time > 0.0 && torque_ != 0.0 && last_sign_ != 0.0 && std::copysign(1.0, torque_) != last_sign_)
          lash_until_ = t + p_.backlash_time;
        if (torque_ != 0.0) last_sign_ = std::copysign(1.0, torque_);
        const bool lash = t < lash_until_;
        const double G = car_.gear_ratio(gear_);
        const double target = cut_until_ > t ? 0.0 : torque_target;
        const double es = torque_ >= 0.0 ? eta : 1.0 / eta;
        // y = [v, x, T_e]
        auto f = [&](double tt, const std::array<double, 3>& y) {
          const double Te = y[2];
          const double e = Te >= 0.0 ? eta : 1.0 / eta;
          const double drive = lash ? 0.0 : e * G * Te / r;
          const double m_eq = lash ? mass_ : mass_ + e * car_.engine_inertia * G * G / (r * r);
          const double a = (drive - load_(tt, std::max(y[0], 0.0), y[1], mass_, drag)) / m_eq;
          const double dT = std::clamp((target - Te) / 0.05, -1500.0, 1500.0);
          return std::array<double, 3>{a, y[0], dT};
        };
        const std::array<double, 3> y{v_, x_, torque_};
        const double a0 = f(t, y)[0];
        const auto y1 = rk4(f, t, y);
        v_ = std::max(y1[0], 0.0);
        x_ = y1[1];
        torque_ = y1[2];
        we_ = G * v_ / r;
        const double wheel = lash ? 0.0 : es * G * (y[2] - car_.engine_inertia * G * a0 / r);
        s.engine_torque = y[2];
        s.wheel_torque = wheel;
        s.ax = a0;
        s.gear = gear_;
        s.gear_ratio = G;
        s.input_speed = G * y[0] / r;
        s.engine_speed = G * y[0] / r;
        clamp_ = std::min(kLockedClampLoad, clamp_ + kClampApplyRate * kDt);
        s.clamp_load = clamp_;
        s.vx = y[0];
        // Upshift: torque cut first, then the clutch opens.
        if (cut_until_ <= t && y[0] > 0.0 && G * y[0] / r > kUpshiftSpeed && gear_ < 5 && torque_target > 0.0 && cut_until_ < 0.0)
          cut_until_ = t + kTorqueCutTime;
        if (cut_until_ > 0.0 && t >= cut_until_) {
          cut_until_ = -1.0;
          mode_ = Mode::kShift;
          shift_start_ = t;
          shift_from_ = we_;
          ++gear_;
          shift_sync0_ = car_.gear_ratio(gear_) * v_ / r;
        }
        break;
      }
      case Mode::kShift: {
        const double G = car_.gear_ratio(gear_);
        auto f = [&](double tt, const std::array<double, 2>& y) {
          return std::array<double, 2>{-load_(tt, std::max(y[0], 0.0), y[1], mass_, drag) / mass_, y[0]};
        };
        const std::array<double, 2> y{v_, x_};
        const double a0 = f(t, y)[0];
        const double tau = t - shift_start_;
        const double gap = shift_from_ - shift_sync0_;
        const double we = G * y[0] / r + gap * 0.5 * (1.0 + std::cos(std::numbers::pi * tau / kShiftTime));
        const double dwe = G * a0 / r - gap * 0.5 * std::numbers::pi / kShiftTime * std::sin(std::numbers::pi * tau / kShiftTime);
        s.engine_speed = we;
        s.engine_torque = car_.engine_inertia * dwe;
        clamp_ = std::max(0.0, clamp_ - kClampReleaseRate * kDt);
        s.clamp_load = clamp_;
        // The synchroniser brings the input shaft to the new gear's speed in 0.2 s.
        const double G_old = car_.gear_ratio(gear_ - 1);
        s.input_speed = (G_old + (G - G_old) * smoothstep(tau / 0.2)) * y[0] / r;
        s.gear = gear_;
        s.gear_ratio = G;
        s.ax = a0;
        s.vx = y[0];
        const auto y1 = rk4(f, t, y);
        v_ = y1[0];
        x_ = y1[1];
        if (tau + kDt >= kShiftTime) {
          mode_ = Mode::kLocked;
          torque_ = car_.engine_inertia * G * a0 / r;
          last_sign_ = 0.0;
        }
        break;
      }
      case Mode::kOpen: {
        auto f = [&](double tt, const std::array<double, 2>& y) {
          const double v = std::max(y[0], 0.0);
          const double brake = car_.brake_gain * brake_pa * std::tanh(v / 0.05);
          return std::array<double, 2>{v > 0.0 ? -(load_(tt, v, y[1], mass_, drag) + brake) / mass_ : 0.0, v};
        };
        const std::array<double, 2> y{v_, x_};
        const double a0 = f(t, y)[0];
        // The idle controller takes the engine back to idle, easing in over 0.3 s. Integrated by
        // RK4 like every other state: the torque J_e dwe recorded at t is then the derivative of
        // the engine speed recorded at t (forward Euler made it the slope to t + dt: half a step
        // late, 0.06 N m against the clutch model's rows).
        auto idle = [&](double tt, const std::array<double, 1>& w) {
          return std::array<double, 1>{(car_.idle_speed - w[0]) / 0.6 * smoothstep((tt - open_since_) / 0.3)};
        };
        const double dwe = idle(t, {we_})[0];
        clamp_ = std::max(0.0, clamp_ - kClampReleaseRate * kDt);
        s.clamp_load = clamp_;
        s.engine_speed = we_;
        s.engine_torque = car_.engine_inertia * dwe;
        s.input_speed = input_;  // the gearbox's drag slows the free input shaft
        input_ -= input_ / 0.4 * kDt;
        s.vx = y[0];
        s.ax = a0;
        s.brake_pressure = brake_pa;
        const auto y1 = rk4(f, t, y);
        v_ = std::max(y1[0], 0.0);
        if (brake_pa > 0.0 && v_ < 0.02) v_ = 0.0;  // held by the brake
        x_ = y1[1];
        we_ = rk4(idle, t, std::array<double, 1>{we_})[0];
        if (v_ == 0.0 && !stopped_) {
          stopped_ = true;
          stop_time_ = t;
        }
        break;
      }
      case Mode::kLaunch: {
        const double G = car_.gear_ratio(1);
        const double tau = t - launch_start_;
        auto clutch_torque_at = [&](double tt) {
          return launch_torque_ * smoothstep((tt - launch_start_) / 0.6);
        };
        const double clutch_torque = clutch_torque_at(t);
        // The clutch torque at each RK4 stage's own time: held over the step, the car's speed
        // would follow the torque half a step late, and the engine's recorded torque (with a0 at
        // t) would not be the one that moves the recorded speeds (0.06 N m on the launch rows).
        auto f = [&](double tt, const std::array<double, 3>& y) {
          const double v = std::max(y[0], 0.0);
          const double drive = eta * G * clutch_torque_at(tt) / r;
          const double res = v > 0.0 || drive > car_.rolling_resistance ? load_(tt, v, y[1], mass_, drag) : drive;
          return std::array<double, 3>{(drive - res) / mass_, v, 0.0};
        };
        const std::array<double, 3> y{v_, x_, 0.0};
        const double a0 = f(t, y)[0];
        // Slip decays exponentially once the controller has taken over (g' eases from 0 to 1).
        const double g = tau - 0.3 * (1.0 - std::exp(-tau / 0.3));
        const double slip = launch_slip0_ * std::exp(-g / 0.45);
        const double dslip = -slip * (1.0 - std::exp(-tau / 0.3)) / 0.45;
        const double win = G * y[0] / r;
        const double mu = clutch_mu(car_, p_, slip, energy_);
        s.engine_speed = win + slip;
        s.engine_torque = car_.engine_inertia * (G * a0 / r + dslip) + clutch_torque;
        s.input_speed = win;
        s.clamp_load = clutch_torque / (car_.clutch_radius * mu);
        clamp_ = s.clamp_load;
        s.wheel_torque = eta * G * clutch_torque;
        s.gear = 1;
        s.gear_ratio = G;
        s.vx = y[0];
        s.ax = a0;
        const auto y1 = rk4(f, t, y);
        v_ = std::max(y1[0], 0.0);
        x_ = y1[1];
        energy_ += clutch_torque * slip * kDt;
        if (slip <= kLockSlip) {
          mode_ = Mode::kLocked;
          gear_ = 1;
          torque_ = s.engine_torque;
          last_sign_ = 0.0;
        }
        break;
      }
    }
    if (s.engine_speed == 0.0) s.engine_speed = we_;
    s.ax += car_.gravity * std::sin(grade_at(p_, x_));  // the accelerometer's specific force
    s.az = car_.gravity;
    s.engine_torque += p_.ecu_torque_offset + p_.torque_per_engine_speed * s.engine_speed;
    return s;
  }

  double drag_pressure(double t) const { return benchcar::drag_pressure(p_, t); }
  double speed() const { return v_; }
  Mode mode() const { return mode_; }
  bool stopped() const { return stopped_; }
  double stop_time() const { return stop_time_; }
  void add_mass(double dm) { mass_ += dm; }
  double energy() const { return energy_; }

 private:
  template <std::size_t N, class F>
  static std::array<double, N> rk4(F f, double t, const std::array<double, N>& y) {
    auto add = [](const std::array<double, N>& a, const std::array<double, N>& b, double h) {
      std::array<double, N> out{};
      for (std::size_t i = 0; i < N; ++i) out[i] = a[i] + h * b[i];
      return out;
    };
    const auto k1 = f(t, y);
    const auto k2 = f(t + kDt / 2, add(y, k1, kDt / 2));
    const auto k3 = f(t + kDt / 2, add(y, k2, kDt / 2));
    const auto k4 = f(t + kDt, add(y, k3, kDt));
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) out[i] = y[i] + kDt / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    return out;
  }
  void start_launch(double t) {
    mode_ = Mode::kLaunch;
    launch_start_ = t;
    launch_slip0_ = we_;  // the engine at idle, the input shaft standing
    launch_torque_ =
        kLaunchTorque * kLaunchTorqueFactors[launches_++ % kLaunchTorqueFactors.size()];
    stopped_ = false;
  }

  const CarParameters& car_;
  const Perturbation& p_;
  RoadLoad load_;
  double mass_;
  double v_;
  double x_ = 0.0;
  double we_;
  double torque_ = 0.0;
  int gear_;
  Mode mode_;
  double cut_until_ = -1.0;
  double shift_start_ = 0.0, shift_from_ = 0.0, shift_sync0_ = 0.0;
  double lash_until_ = -1.0;
  double last_sign_ = 0.0;
  bool stopped_ = false;
  double stop_time_ = 0.0;
  double launch_start_ = 0.0, launch_slip0_ = 0.0, launch_torque_ = kLaunchTorque;
  std::size_t launches_ = 0;
  double energy_ = 0.0;
  double input_ = 0.0;  // rad/s, the free input shaft in neutral
  double clamp_ = kLockedClampLoad;  // N, the actuator's load
  double open_since_ = 0.0;
};

Truth longitudinal(const CarParameters& car, const Perturbation& p, std::uint64_t seed) {
  std::mt19937_64 rng(seed * 7919 + 11);
  const double phase = std::uniform_real_distribution<double>(0.0, kTwoPi)(rng);
  const double duration = 42.0;
  Driveline d(car, p, 4.0, 1);
  const double cruise = (0.5 * car.air_density * car.scx * 16.0 + car.rolling_resistance) * car.wheel_radius /
                        (car.efficiency * car.gear_ratio(1));
  std::vector<double> time;
  std::vector<Sample> samples;
  double brake_start = -1.0;
  bool mass_added = false;
  double mass_added_at = std::numeric_limits<double>::quiet_NaN();
  bool relaunched = false;
  for (int k = 0; k * kDt < duration; ++k) {
    const double t = k * kDt;
    double target = 0.0;
    // A steady start (the filter's first samples see no transient), then full acceleration.
    if (t < 1.5) target = cruise;
    else if (t < 13.0) target = cruise + (170.0 + 60.0 * std::sin(kTwoPi * 0.3 * t + phase) - cruise) * smoothstep(t - 1.5);
    else if (t < 16.0) target = -30.0;
    else if (t < 17.5) target = 110.0;
    else if (t < 19.5) target = -30.0;
    else if (t < 22.8) target = 150.0;
    else if (t < 23.0) target = 0.0;  // the driver lifts off before braking
    else target = 160.0 + 50.0 * std::sin(kTwoPi * 0.35 * t + phase);
    double brake = 0.0;
    bool launch = false;
    if (t >= 23.0 && brake_start < 0.0) brake_start = t;
    if (brake_start >= 0.0 && !d.stopped() && !relaunched) brake = 12e5 * smoothstep((t - brake_start) / 0.1);
    if (d.stopped()) {
      brake = 0.0;
      if (!mass_added && t >= d.stop_time() + 1.2) {
        d.add_mass(p.mass_step);
        mass_added = true;
        mass_added_at = t;
      }
      launch = t >= d.stop_time() + 2.5;
      relaunched = relaunched || launch;
    }
    Sample s = d.step(t, target, brake, launch);
    if (brake == 0.0 && d.mode() != Driveline::Mode::kOpen && p.brake_drag_pressure > 0.0)
      s.brake_pressure = d.drag_pressure(t);
    time.push_back(t);
    samples.push_back(s);
  }
  Truth truth = make_truth(time, samples);
  truth.parameters = {{"mass", car.mass},
                      {"SCx", car.scx},
                      {"rolling_resistance", car.rolling_resistance},
                      {"engine_inertia", car.engine_inertia}};
  if (p.mass_step != 0.0) truth.change_time_s = mass_added_at;
  return truth;
}

// Smooth cruise in fourth gear: no shift, no brake, slow throttle sines (0.05 and 0.1 Hz) between
// steady states. The exactness run: the central difference's error on d_vx, (h w)^2 / 6, is below
// 1e-5 at these frequencies.
Truth cruise(const CarParameters& car, const Perturbation& p) {
  const double duration = 40.0;
  const double v0 = 15.0;
  Driveline d(car, p, v0, 4);
  const double steady = (0.5 * car.air_density * car.scx * v0 * v0 + car.rolling_resistance) * car.wheel_radius /
                        (car.efficiency * car.gear_ratio(4));
  std::vector<double> time;
  std::vector<Sample> samples;
  for (int k = 0; k * kDt < duration; ++k) {
    const double t = k * kDt;
    const double window = smoothstep((t - 2.0) / 4.0) * (1.0 - smoothstep((t - 34.0) / 4.0));
    const double target = steady + window * (60.0 * std::sin(kTwoPi * 0.05 * (t - 2.0)) + 40.0 * std::sin(kTwoPi * 0.1 * (t - 2.0)) + 40.0);
    time.push_back(t);
    samples.push_back(d.step(t, target, 0.0, false));
  }
  Truth truth = make_truth(time, samples);
  truth.parameters = {{"mass", car.mass}, {"SCx", car.scx}, {"rolling_resistance", car.rolling_resistance},
                      {"engine_inertia", car.engine_inertia}};
  return truth;
}

Truth launch(const CarParameters& car, const Perturbation& p, std::uint64_t /*seed*/) {
  const double duration = 36.0;
  Driveline d(car, p, 0.0, 0);
  std::vector<double> time;
  std::vector<Sample> samples;
  double next_launch = 1.5;
  double locked_since = -1.0;
  bool braking = false;
  for (int k = 0; k * kDt < duration; ++k) {
    const double t = k * kDt;
    double brake = 0.0;
    bool launch = false;
    if (d.mode() == Driveline::Mode::kOpen && !braking && t >= next_launch) launch = true;
    if (d.mode() == Driveline::Mode::kLocked && locked_since < 0.0) locked_since = t;
    if (locked_since >= 0.0 && t >= locked_since + 2.5) braking = true;
    if (braking) {
      brake = 10e5;
      if (d.stopped()) {
        braking = false;
        locked_since = -1.0;
        next_launch = t + 1.5;
        brake = 0.0;
      }
    }
    // The driver lifts off 0.3 s before braking.
    const bool lift = locked_since >= 0.0 && t >= locked_since + 2.2;
    Sample s = d.step(t, lift ? 0.0 : 150.0, brake, launch);
    time.push_back(t);
    samples.push_back(s);
  }
  Truth truth = make_truth(time, samples);
  truth.parameters = {{"engine_inertia", car.engine_inertia},
                      {"coulomb_friction", car.clutch_mu_coulomb},
                      {"viscous_friction", car.clutch_mu_viscous}};
  // clutch_torque_curve with the car's touch point and 4 knots (0.3625, 0.575, 0.7875, 1): the
  // launches' loads (up to ~4 kN, engagement ~0.55) reach the first two; the others have no slip.
  for (int j = 1; j <= 2; ++j) {
    const double load = kLockedClampLoad * (j / 4.0);  // at knot j, (e_j - tp) / (1 - tp) = j / 4
    truth.parameters["clutch_torque_" + std::to_string(j)] =
        car.clutch_mu_coulomb * car.clutch_radius * load;
    truth.parameters["clutch_viscous_" + std::to_string(j)] =
        car.clutch_mu_viscous * car.clutch_radius * load;
  }
  return truth;
}

Truth lateral(const CarParameters& car, const Perturbation& p, std::uint64_t seed) {
  std::mt19937_64 rng(seed * 104729 + 3);
  std::uniform_real_distribution<double> ph(0.0, kTwoPi);
  const std::array<double, 4> freq = {0.2, 0.45, 0.8, 1.2};
  std::array<double, 4> phase{};
  for (double& x : phase) x = ph(rng);
  const double duration = 30.0;
  const double vx = 20.0;
  const double M = car.mass;
  const int gear = 4;
  const double G = car.gear_ratio(gear);
  std::vector<double> time;
  std::vector<Sample> samples;
  // y = [vy, r, alpha_f, alpha_r] (the lagged slip angles when relaxation is on)
  std::array<double, 4> y{};
  double ay_prev = 0.0;
  auto steer_at = [&](double t) {
    double d = 0.0;
    for (std::size_t i = 0; i < 4; ++i) d += 0.010 * std::sin(kTwoPi * freq[i] * t + phase[i]);
    return d * smoothstep(t / 2.0);
  };
  auto forces = [&](double t, const std::array<double, 4>& s, double ay_load, double& ff, double& fr, std::array<double, 2>& kin) {
    const double delta = steer_at(t);
    kin[0] = delta - std::atan((s[0] + car.a * s[1]) / vx);
    kin[1] = -std::atan((s[0] - car.b * s[1]) / vx);
    const double af = p.relaxation_length > 0.0 ? s[2] : kin[0];
    const double ar = p.relaxation_length > 0.0 ? s[3] : kin[1];
    double cf = car.front_cornering * (1.0 + p.front_stiffness_drift * (t - duration / 2.0) / duration);
    double cr = car.rear_cornering * (t >= p.step_time ? 1.0 + p.rear_stiffness_step : 1.0);
    const double load = 1.0 - p.load_sensitivity * ay_load * ay_load;
    cf *= load;
    cr *= load;
    ff = cf * af;
    fr = cr * ar;
    return delta;
  };
  auto f = [&](double t, const std::array<double, 4>& s) {
    double ff = 0, fr = 0;
    std::array<double, 2> kin{};
    const double delta = forces(t, s, ay_prev, ff, fr, kin);
    const double ay = (ff * std::cos(delta) + fr) / M;
    std::array<double, 4> d{};
    d[0] = ay - vx * s[1];
    d[1] = (car.a * ff * std::cos(delta) - car.b * fr) / car.yaw_inertia;
    if (p.relaxation_length > 0.0) {
      d[2] = vx / p.relaxation_length * (kin[0] - s[2]);
      d[3] = vx / p.relaxation_length * (kin[1] - s[3]);
    }
    return d;
  };
  const double drive_force = 0.5 * car.air_density * car.scx * vx * vx + car.rolling_resistance;
  for (int k = 0; k * kDt < duration; ++k) {
    const double t = k * kDt;
    double ff = 0, fr = 0;
    std::array<double, 2> kin{};
    const double delta = forces(t, y, ay_prev, ff, fr, kin);
    Sample s;
    s.vx = vx;
    s.vy = y[0];
    s.yaw_rate = y[1];
    s.ay = (ff * std::cos(delta) + fr) / M;
    s.ax = -y[0] * y[1];
    s.az = car.gravity;
    s.steer = delta;
    s.gear = gear;
    s.gear_ratio = G;
    s.engine_speed = G * vx / car.wheel_radius;
    s.input_speed = s.engine_speed;
    s.engine_torque = drive_force * car.wheel_radius / (car.efficiency * G) + p.ecu_torque_offset;
    s.wheel_torque = drive_force * car.wheel_radius;
    s.clamp_load = kLockedClampLoad;
    ay_prev = s.ay;
    time.push_back(t);
    samples.push_back(s);
    // RK4
    auto add = [](const std::array<double, 4>& a, const std::array<double, 4>& b, double h) {
      std::array<double, 4> out{};
      for (std::size_t i = 0; i < 4; ++i) out[i] = a[i] + h * b[i];
      return out;
    };
    const auto k1 = f(t, y);
    const auto k2 = f(t + kDt / 2, add(y, k1, kDt / 2));
    const auto k3 = f(t + kDt / 2, add(y, k2, kDt / 2));
    const auto k4 = f(t + kDt, add(y, k3, kDt));
    for (std::size_t i = 0; i < 4; ++i) y[i] += kDt / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  }
  Truth truth = make_truth(time, samples);
  // lateral_bicycle_no_vy's yaw terms (lateral_no_vy.hpp), from the same car.
  const double wheelbase = car.a + car.b, stiffnesses = car.front_cornering * car.rear_cornering;
  truth.parameters = {
      {"yaw_inertia", car.yaw_inertia},
      {"front_cornering_stiffness", car.front_cornering},
      {"rear_cornering_stiffness", car.rear_cornering},
      {"steer_per_yaw_acceleration",
       car.yaw_inertia * (car.front_cornering + car.rear_cornering) / (wheelbase * stiffnesses)},
      {"understeer_gradient",
       M * (car.b * car.rear_cornering - car.a * car.front_cornering) / (wheelbase * stiffnesses)}};
  if (p.rear_stiffness_step != 0.0) truth.change_time_s = p.step_time;
  return truth;
}

}  // namespace

const char* manoeuvre_name(Manoeuvre m) {
  switch (m) {
    case Manoeuvre::kLongitudinal: return "longitudinal";
    case Manoeuvre::kLateral: return "lateral";
    case Manoeuvre::kLaunch: return "launch";
    case Manoeuvre::kCruise: return "cruise";
  }
  return "?";
}

Truth simulate(Manoeuvre manoeuvre, const CarParameters& car, const Perturbation& perturbation, std::uint64_t seed) {
  switch (manoeuvre) {
    case Manoeuvre::kLongitudinal: return longitudinal(car, perturbation, seed);
    case Manoeuvre::kLateral: return lateral(car, perturbation, seed);
    case Manoeuvre::kLaunch: return launch(car, perturbation, seed);
    case Manoeuvre::kCruise: return cruise(car, perturbation);
  }
  return {};
}

}  // namespace dynid::benchcar
