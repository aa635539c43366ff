#include "dynid/sim/tyre.hpp"

#include <algorithm>
#include <cmath>

namespace dynid::sim {

double lateral_force(double alpha, double c, double mu_fz, bool saturation) {
  const double z = std::tan(alpha);
  if (!saturation) return c * z;
  if (mu_fz <= 0.0) return 0.0;
  // Fiala: cubic up to the sliding angle, where it meets mu Fz with zero slope.
  const double z_slide = 3.0 * mu_fz / c;
  if (std::abs(z) >= z_slide) return std::copysign(mu_fz, z);
  return c * z - c * c / (3.0 * mu_fz) * std::abs(z) * z + c * c * c / (27.0 * mu_fz * mu_fz) * z * z * z;
}

double cornering_stiffness_at_load(double c0, double fz, double fz0, double k) {
  const double ratio = fz / fz0;
  return std::max(0.0, c0 * ratio * (1.0 - k * (ratio - 1.0)));
}

}  // namespace dynid::sim
