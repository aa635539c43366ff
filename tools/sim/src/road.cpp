#include "dynid/sim/road.hpp"

#include <cmath>
#include <string>

#include "dynid/error.hpp"
#include "dynid/sim/parameters.hpp"

namespace dynid::sim {

Profile::Profile(std::vector<std::pair<double, double>> points) : points_(std::move(points)) {
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (!std::isfinite(points_[i].first) || !std::isfinite(points_[i].second))
      throw InputError("road profile: point " + std::to_string(i) + " is not finite");
    if (i > 0 && points_[i].first <= points_[i - 1].first)
      throw InputError("road profile: distances must increase strictly (point " +
                       std::to_string(i) + ")");
  }
}

double Profile::at(double distance) const {
  if (points_.empty()) return 0.0;
  if (distance <= points_.front().first) return points_.front().second;
  if (distance >= points_.back().first) return points_.back().second;
  std::size_t i = 1;
  while (points_[i].first < distance) ++i;
  const auto& [s0, v0] = points_[i - 1];
  const auto& [s1, v1] = points_[i];
  return v0 + (v1 - v0) * (distance - s0) / (s1 - s0);
}

std::array<double, 3> gravity_in_road_frame(double grade, double bank) {
  // Uphill grade pulls backwards; a bank that raises the left side pulls to the right.
  return {-kGravity * std::sin(grade), -kGravity * std::cos(grade) * std::sin(bank),
          -kGravity * std::cos(grade) * std::cos(bank)};
}

}  // namespace dynid::sim
