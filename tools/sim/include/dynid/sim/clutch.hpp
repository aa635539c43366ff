#pragma once
// Clutch friction coefficient: Borsotto's Stribeck model (borsotto-2008 §2.5, final clutch mu
// model, delta_s = 2):
//   mu(dw) = (mu_c + (mu_s - mu_c) exp(-(dw/v_s)^2)) sgn(dw) + mu_v dw,
// and the clutch torque mu(dw) R_eq F_n (eq. 4.15), dw = engine speed - gearbox input speed.
//
// Contract: with `stribeck` false mu_s is replaced by mu_c; with `viscous` false mu_v = 0.
// mu(0) = 0: the stuck clutch is handled by the simulator's stick/slip state machine, which
// asks static_capacity() whether the locked clutch can carry the required torque.
#include "dynid/sim/parameters.hpp"

namespace dynid::sim {

struct ClutchFriction {
  double mu_static = 0.0;
  double mu_coulomb = 0.0;
  double mu_viscous = 0.0;
  double stribeck_speed = 1.0;
  double radius = 0.0;

  static ClutchFriction from(const DrivelineParameters& d, bool stribeck, bool viscous);
  double mu(double slip_speed) const;
  double torque(double slip_speed, double clamp_load) const {
    return mu(slip_speed) * radius * clamp_load;
  }
  // Largest torque the stuck clutch transmits, N m.
  double static_capacity(double clamp_load) const { return mu_static * radius * clamp_load; }
};

}  // namespace dynid::sim
