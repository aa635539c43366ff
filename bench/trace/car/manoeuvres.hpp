#pragma once
// The second car's three manoeuvres, integrated at 1 kHz (RK4), each returning every channel
// its sensors measure (truth.hpp) with a family's perturbation applied to the physics:
//   longitudinal  ~42 s: from 4 m/s in first gear, full acceleration through the gears with a
//                 sinusoidal throttle, lift-offs and tip-ins (torque reversals), braking to a
//                 stop in neutral, 2.5 s standing, a clutch launch and acceleration again.
//                 Read by longitudinal_wheel and longitudinal_engine.
//   lateral       30 s at 20 m/s, a sum of four steering sines (0.2 .. 1.2 Hz, random phases):
//                 linear single-track dynamics. Read by lateral_bicycle.
//   launch        36 s: four standing starts, each with a slip-controlled clutch engagement
//                 (clutch torque prescribed, slip decaying exponentially to lock), 2.5 s in
//                 first gear, then clutch open and brake to a stop. Read by clutch_slip.
//   cruise        40 s in fourth gear from 15 m/s, slow throttle sines, no shift or brake: the
//                 smoke test's exactness run.
// Why prescribed clutch torque and slip on launches (an inverse simulation): the clamp load
// that produces them follows from the friction law, so every channel is consistent with the
// law by construction, and the slip's slow tail covers the Stribeck region that a feedback
// launch crosses in a tenth of a second.
#include <cstdint>
#include <string>

#include "parameters.hpp"
#include "perturbation.hpp"
#include "truth.hpp"

namespace dynid::benchcar {

enum class Manoeuvre { kLongitudinal, kLateral, kLaunch, kCruise };
const char* manoeuvre_name(Manoeuvre m);

Truth simulate(Manoeuvre manoeuvre, const CarParameters& car, const Perturbation& perturbation,
               std::uint64_t seed);

}  // namespace dynid::benchcar
