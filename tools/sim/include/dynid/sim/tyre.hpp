#pragma once
// Lateral tyre force: Fiala's brush model with a friction limit (nehaoua §2.6, sign as in §2.2:
// a positive slip angle gives a positive force), and the cornering stiffness's dependence on
// the vertical load.
//
// Contract: the slope at zero slip is exactly the cornering stiffness C (N/rad), which is the
// truth the lateral models identify; the force is continuous and saturates at +-mu Fz beyond
// the sliding angle atan(3 mu Fz / C). With `saturation` false the tyre is linear: C tan(alpha).
namespace dynid::sim {

// alpha in rad; fz >= 0 (N), the friction force available laterally mu_fz >= 0 (N).
double lateral_force(double alpha, double cornering_stiffness, double mu_fz, bool saturation);

// C(Fz) = C0 (Fz/Fz0) (1 - k (Fz/Fz0 - 1)): equal to C0 at the static load Fz0, degressive
// (the sum over an axle drops under lateral load transfer, as with real tyres), 0 at Fz = 0.
// k = 0 gives a stiffness proportional to the load. Never negative.
double cornering_stiffness_at_load(double c0, double fz, double fz0, double k);

}  // namespace dynid::sim
