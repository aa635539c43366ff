#include "dynid/sim/clutch.hpp"

#include <cmath>

namespace dynid::sim {

ClutchFriction ClutchFriction::from(const DrivelineParameters& d, bool stribeck, bool viscous) {
  ClutchFriction f;
  f.mu_coulomb = d.clutch_mu_coulomb;
  f.mu_static = stribeck ? d.clutch_mu_static : d.clutch_mu_coulomb;
  f.mu_viscous = viscous ? d.clutch_mu_viscous : 0.0;
  f.stribeck_speed = d.clutch_stribeck_speed;
  f.radius = d.clutch_radius;
  return f;
}

double ClutchFriction::mu(double dw) const {
  if (dw == 0.0) return 0.0;
  const double x = dw / stribeck_speed;
  const double level = mu_coulomb + (mu_static - mu_coulomb) * std::exp(-x * x);
  return std::copysign(level, dw) + mu_viscous * dw;
}

}  // namespace dynid::sim
