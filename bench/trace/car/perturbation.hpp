#pragma once
// What a benchmark family injects into the second car's simulated truth (never into the model):
// environment, physics and sensor departures from the car as its profile describes it. A
// default-constructed Perturbation is the clean car.
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace dynid::benchcar {

struct Perturbation {
  // Environment
  std::vector<std::pair<double, double>> grade;  ///< (distance m, grade rad), piecewise linear
  double head_wind = 0.0;           ///< m/s, constant
  double gust_amplitude = 0.0;      ///< m/s per component of a random gust (sum of 4 sines)
  double brake_drag_pressure = 0.0; ///< Pa, mean: the driver rides the brake while driving (varies)
  double mass_step = 0.0;           ///< kg added at the stop of the longitudinal run
  // Driveline
  double torque_per_engine_speed = 0.0;  ///< N m per rad/s: the ECU over-reports T_e by c w_e
  double backlash_time = 0.0;       ///< s without torque transfer after each torque reversal
  double ecu_torque_offset = 0.0;   ///< N m: the ECU reports T_e + offset
  // Lateral
  double rear_stiffness_step = 0.0;  ///< relative change of C_r at step_time
  double step_time = 0.0;            ///< s
  double front_stiffness_drift = 0.0;  ///< relative change of C_f over the whole run (linear)
  double load_sensitivity = 0.0;     ///< C(ay) = C (1 - k ay^2), k in s^4/m^2
  double relaxation_length = 0.0;    ///< m: slip angles lag by a first-order sigma / vx
  // Clutch
  double clutch_fade = 0.0;          ///< relative loss of mu_c per 100 kJ dissipated
  double stribeck_rise = 0.0;        ///< mu_s - mu_c
  double stribeck_speed = 0.0;       ///< rad/s
  // Sensors
  std::map<std::string, double> delay;  ///< channel -> s late
  double imu_roll_mount = 0.0;       ///< rad: the lateral accelerometer reads ay cos + g sin
  double wheel_torque_scale = 1.0;   ///< the wheel-torque meter's gain error
  std::uint64_t seed = 0;            ///< for gust phases etc.
};

}  // namespace dynid::benchcar
