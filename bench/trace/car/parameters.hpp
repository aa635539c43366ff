#pragma once
// The benchmark's second car (bench/trace, issue 15): a 1850 kg rear-driven SUV, written
// independently of the reference simulator (tools/sim), with its own geometry, tyres, drag,
// driveline and clutch. These are the truths the benchmark compares the product's estimates
// with; bench/trace/benchcar.toml holds the constants an engineer would know (geometry, the
// weighed mass, radii), not the identified ones.
#include <array>

namespace dynid::benchcar {

struct CarParameters {
  // Body and tyres
  double mass = 1850.0;            // kg, translating (wheels' rotary inertia included)
  double a = 1.32;                 // m, CG to front axle
  double b = 1.58;                 // m, CG to rear axle
  double yaw_inertia = 3150.0;     // kg m^2
  double front_cornering = 98000.0;   // N/rad, axle
  double rear_cornering = 112000.0;   // N/rad, axle
  double steering_ratio = 15.2;
  // Road load
  double scx = 0.98;               // m^2 (Cx 0.36 x 2.72 m^2)
  double rolling_resistance = 218.0;  // N (0.012 M g)
  double air_density = 1.2;        // kg/m^3
  double gravity = 9.80665;
  double brake_gain = 600.0e-5;    // N/Pa (600 N/bar, all four wheels)
  // Driveline (rear-wheel drive, 5 gears)
  double wheel_radius = 0.365;     // m
  double final_drive = 3.9;
  std::array<double, 5> gearbox = {4.1, 2.4, 1.55, 1.12, 0.9};
  double efficiency = 0.93;
  double engine_inertia = 0.21;    // kg m^2
  double idle_speed = 94.0;        // rad/s (900 rpm)
  // Clutch: mu(dw) = mu_c + mu_v dw (+ a Stribeck hump when a family adds one)
  double clutch_radius = 0.24;     // m, equivalent radius x two faces
  double clutch_mu_coulomb = 0.29;
  double clutch_mu_viscous = -3.0e-4;  // s/rad: the facing's mu falls slightly with slip
  // The actuator's travel (clutch_engagement, 0 open .. 1 closed): the load is 0 up to the touch
  // point and rises linearly to the diaphragm spring's full load at 1.
  double clutch_full_load = 9000.0;  // N
  double clutch_touch_point = 0.15;
  double clutch_engagement(double clamp_load) const {
    return clutch_touch_point +
           (1.0 - clutch_touch_point) * (clamp_load > 0.0 ? clamp_load : 0.0) / clutch_full_load;
  }

  double gear_ratio(int gear) const { return gear <= 0 ? 0.0 : gearbox[static_cast<unsigned>(gear - 1)] * final_drive; }
};

}  // namespace dynid::benchcar
