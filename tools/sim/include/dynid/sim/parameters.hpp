#pragma once
// The simulated car's physical parameters: the "truth" every identification model is checked
// against. SI units throughout.
//
// Contract: default_parameters() is the reference car of the project: the body, suspensions,
// anti-roll bars and tyre vertical stiffness of Venture's Peugeot 406 (venture-2003 §6.0), the
// driveline and clutch of Borsotto's Renault Clio (borsotto-2008 §1.5, §2.5: inertias, driveshaft
// stiffness and damping, overall gear ratios, Stribeck clutch friction), cornering stiffnesses and
// tyre friction chosen in the range of Nehaoua's course (nehaoua §8), aero and rolling resistance
// typical of a saloon. Values the sources do not give are marked "assumed" where they are set.
// Geometry: the reference point O is on the ground under the static centre of gravity; x forward,
// y left, z up (ISO 8855); corners fl, fr, rl, rr (index 0..3).
#include <array>
#include <string>
#include <utility>
#include <vector>

namespace dynid::sim {

inline constexpr double kGravity = 9.81;
inline constexpr int kCorners = 4;  // fl, fr, rl, rr
inline constexpr std::array<const char*, kCorners> kCornerNames{"fl", "fr", "rl", "rr"};

struct VehicleParameters {
  // Masses and inertias.
  double mass = 1508.5;               // total, kg (venture §6.0)
  double unsprung_mass_front = 40.0;  // per corner, kg (assumed)
  double unsprung_mass_rear = 35.0;   // per corner, kg (assumed)
  double yaw_inertia = 2342.0;        // whole car about the vertical axis through G, kg m^2
  double roll_inertia = 622.0;        // sprung mass about x through its CG, kg m^2
  double pitch_inertia = 2041.0;      // sprung mass about y through its CG, kg m^2
  // Geometry.
  double cg_to_front_axle = 1.091;  // a, m
  double cg_to_rear_axle = 1.601;   // b, m
  double track_front = 1.50;        // m
  double track_rear = 1.48;         // m
  double cg_height = 0.55;          // sprung-mass CG above ground, m (assumed)
  double aero_height = 0.50;        // height of the drag force, m (assumed)
  // Wheels and tyres.
  double wheel_radius = 0.30;                     // m
  double wheel_inertia = 0.6759;                  // spin inertia per wheel, kg m^2 (borsotto J_r)
  double cornering_stiffness_front = 60000.0;     // per tyre at static load, N/rad
  double cornering_stiffness_rear = 55000.0;      // per tyre at static load, N/rad
  double tyre_load_sensitivity = 0.2;             // degressivity of C(Fz), see tyre.hpp
  double tyre_friction = 1.0;                     // mu
  double tyre_vertical_stiffness = 200000.0;      // N/m (venture §6.0)
  // Suspension (wheel rates), per corner front / rear.
  double spring_front = 20600.0;          // N/m (venture)
  double spring_rear = 22000.0;           // N/m
  double damping_front = 3200.0;          // N s/m (venture)
  double damping_rear = 3800.0;           // N s/m
  double damping_quadratic_front = 1500.0;  // |v| v term, N s^2/m^2 (assumed)
  double damping_quadratic_rear = 1800.0;
  double suspension_friction = 40.0;        // dry friction per corner, N (venture L3965)
  double suspension_friction_speed = 0.005; // smoothing speed of sign(), m/s
  double arb_front = 19033.0;               // N/m, force k (s_left - s_right) (venture)
  double arb_rear = 19938.0;
  // Resistances.
  double scx = 0.62;                  // drag area S Cx, m^2 (assumed)
  double air_density = 1.225;         // kg/m^3
  double head_wind = 0.0;             // m/s of air against the car (an effect no model declares)
  double rolling_resistance = 0.011;  // coefficient f_r (force = f_r Fz per tyre)
  double brake_drag_torque = 4.0;     // residual pad drag per wheel, N m (assumed)
  double brake_gain_front = 2.0e-4;   // brake torque per wheel per master-cylinder Pa, N m/Pa
  double brake_gain_rear = 0.8e-4;
  double steering_ratio = 16.0;  // steering-wheel angle / road-wheel angle (for the CAN signal)
  // IMU position relative to O (body axes at rest), m: default at the sprung CG.
  std::array<double, 3> imu_position{0.0, 0.0, 0.55};

  double wheelbase() const { return cg_to_front_axle + cg_to_rear_axle; }
  double sprung_mass() const { return mass - 2.0 * (unsprung_mass_front + unsprung_mass_rear); }
  double unsprung_mass(int corner) const {
    return corner < 2 ? unsprung_mass_front : unsprung_mass_rear;
  }
  // Corner position (x, y) relative to O.
  double corner_x(int corner) const { return corner < 2 ? cg_to_front_axle : -cg_to_rear_axle; }
  double corner_y(int corner) const {
    const double half = 0.5 * (corner < 2 ? track_front : track_rear);
    return corner % 2 == 0 ? half : -half;
  }
  // Static vertical tyre load at a corner on a flat road, N.
  double static_tyre_load(int corner) const;
  // Static suspension force at a corner (tyre load minus unsprung weight), N.
  double static_spring_force(int corner) const;
  // Mass the longitudinal motion accelerates: the car plus the spin inertia of the 4 wheels.
  double longitudinal_equivalent_mass() const {
    return mass + 4.0 * wheel_inertia / (wheel_radius * wheel_radius);
  }
};

struct DrivelineParameters {
  double engine_inertia = 0.1806;           // J_m, engine + flywheel, kg m^2 (borsotto)
  double gearbox_input_inertia = 7.67e-3;   // J_1, kg m^2
  double driveshaft_inertia = 0.152;        // J_t, each side, kg m^2
  double driveshaft_stiffness = 15000.0;    // k_t, each side, N m/rad
  double driveshaft_damping = 150.0;        // beta_t, each side, N m s/rad
  std::vector<double> gear_ratios{16.24, 8.92, 6.07, 4.49, 3.57};  // overall (box x final)
  // Clutch: torque = mu(slip) * effective_radius * clamp load (borsotto eq. 4.15, 2.5).
  double clutch_radius = 0.11;            // R_eq, m (assumed for a car clutch)
  double clutch_mu_static = 0.168;        // mu_Fs
  double clutch_mu_coulomb = 0.159;       // mu_Fc
  double clutch_mu_viscous = 3.69e-3;     // mu_sigma_v, s/rad
  double clutch_stribeck_speed = 0.177;   // mu_vs, rad/s
  double clutch_max_clamp_load = 12000.0; // N
  // Engine.
  double engine_max_torque = 250.0;     // N m
  double engine_idle_speed = 89.0;      // rad/s (850 rpm)
  double idle_governor_gain = 3.0;      // N m per rad/s below idle
  double engine_drag_constant = 8.0;    // N m, friction when the throttle is closed
  double engine_drag_viscous = 0.03;    // N m s/rad
  double gearbox_drag = 0.3;            // input-shaft drag in neutral, N m

  double ratio(int gear) const;  // overall ratio of gear 1..n; 0 for neutral
  int gear_count() const { return static_cast<int>(gear_ratios.size()); }
  // J_1 + 2 J_t / alpha^2: what the gearbox input carries when the driveshafts twist.
  double input_side_inertia(int gear) const;
};

struct CarParameters {
  VehicleParameters vehicle;
  DrivelineParameters driveline;
};

CarParameters default_parameters();

// Every scalar parameter by name (for scenario overrides): "vehicle.mass", "driveline.clutch_radius".
std::vector<std::pair<std::string, double*>> named_parameters(CarParameters& car);

}  // namespace dynid::sim
