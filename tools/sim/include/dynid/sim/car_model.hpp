#pragma once
// The car's equations of motion: a planar vehicle (vx, vy, yaw) carrying a sprung body that
// heaves, rolls and pitches on four suspensions over four unsprung masses on vertical tyre
// springs, and a front-wheel-drive driveline (engine, Stribeck clutch, gearbox, compliant
// driveshafts: borsotto-2008 eq. 4.12). State derivatives for a fixed-step integrator.
//
// Equations (small body angles; O = ground point under the static CG, yaw frame axes):
//   M_eq (dvx - r vy) + m_s h ddtheta = sum Fx + M g_x - D          (D: aero drag)
//   M    (dvy + r vx) - m_s h ddphi   = sum Fy + M g_y
//   Izz dr = sum Mz
//   (Ixs + m_s h^2) ddphi   - m_s h (dvy + r vx) = sum y_i F_i + m_s g h phi - m_s h g_y
//   (Iys + m_s h^2) ddtheta + m_s h (dvx - r vy) = -sum x_i F_i + m_s g h theta + m_s h g_x - h_a D
//   m_s ddz = sum F_i + m_s g_z ;  m_u ddzu_i = Fz_i - F_i + m_u g_z
// where the link forces act at ground level (roll and pitch centres on the ground), F_i is the
// suspension force at corner i (spring + damper + |v|v + dry friction + anti-roll bar), Fz_i the
// tyre load. The wheels roll without longitudinal slip; their spin inertia is in M_eq.
// Driveline: J_m dwe = T_e - T_c;  J1' dw1 = T_c - T_s/alpha;  dtheta_s = w1/alpha - vx/R;
// T_s = k theta_s + beta dtheta_s (both shafts), the driven (front) wheels' torque.
// With the clutch stuck, w_e = w1 and (J_m + J1') dw = T_e - T_s/alpha.
//
// Contract: evaluate() is a pure function of its arguments.
#include <array>
#include <cstddef>

#include "dynid/sim/effects.hpp"
#include "dynid/sim/parameters.hpp"
#include "dynid/sim/road.hpp"

namespace dynid::sim {

// Indices into the state vector.
enum StateIndex : std::size_t {
  kX, kY, kPsi, kVx, kVy, kR,
  kZ, kPhi, kTheta, kDz, kDphi, kDtheta,
  kZu0, kZu1, kZu2, kZu3, kDzu0, kDzu1, kDzu2, kDzu3,
  kWEngine, kWInput, kShaftTwist, kDistance,
  kStateSize
};
using State = std::array<double, kStateSize>;

// What the driver commands, held over one integration step.
struct DriverInputs {
  double steer = 0.0;           // road-wheel angle, rad
  double throttle_torque = 0.0; // engine torque requested, N m (before drag and governor)
  double clamp_load = 0.0;      // clutch normal load, N
  int gear = 0;                 // 0 neutral
  double brake_pressure = 0.0;  // Pa
};

// Discrete modes switched between steps.
struct Mode {
  bool clutch_locked = false;
};

// Everything evaluate() computes on the way: the sensors read from it.
struct Evaluation {
  State derivative{};
  std::array<double, kCorners> tyre_load{};         // Fz, N
  std::array<double, kCorners> tyre_fx{};           // in the yaw frame, N
  std::array<double, kCorners> tyre_fy{};
  std::array<double, kCorners> suspension_force{};  // on the body, N
  std::array<double, kCorners> travel{};            // compression, m
  std::array<double, kCorners> travel_rate{};
  std::array<double, kCorners> tyre_deflection{};   // m (static deflection included)
  std::array<double, kCorners> wheel_speed{};       // circumferential, m/s
  double engine_torque = 0.0;        // net, N m
  double clutch_torque = 0.0;        // transmitted, N m
  double locked_clutch_torque = 0.0; // what a stuck clutch would have to carry, N m
  double shaft_torque = 0.0;         // sum of the driven wheels' torques, N m
  double aero_drag = 0.0;            // N
  std::array<double, 3> gravity{};   // yaw frame, m/s^2
  double grade = 0.0;
  double bank = 0.0;
};

struct CarModel {
  CarParameters car;
  Effects effects;
  Road road;

  Evaluation evaluate(const State& s, const DriverInputs& in, const Mode& mode) const;
  // Steady straight driving at `speed` in `gear` (clutch locked unless gear is 0): body at its
  // static equilibrium, driveshafts twisted by the road load.
  State initial_state(double speed, int gear) const;
  // Road load at the wheels for a steady speed on a flat road, N (rolling + aero + brake drag).
  double road_load_force(double speed) const;
  // Shaft stiffness and damping (both shafts) as simulated.
  double shaft_stiffness() const;
  double shaft_damping() const;
};

}  // namespace dynid::sim
