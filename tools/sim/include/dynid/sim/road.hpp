#pragma once
// Road profiles: grade and bank as functions of the distance travelled.
//
// Contract: a Profile is piecewise linear through its (distance m, value rad) points, sorted by
// distance, and constant beyond the first and last point; an empty profile is 0 everywhere.
// Grade is positive uphill, bank positive when it raises the left side (docs/CHANNELS.md).
// The gravity vector in the vehicle's yaw frame follows from both (small slopes of a real road,
// the road plane's own rotation rate is neglected).
#include <array>
#include <utility>
#include <vector>

namespace dynid::sim {

class Profile {
 public:
  Profile() = default;
  // Throws InputError if the distances are not strictly increasing or a value is not finite.
  explicit Profile(std::vector<std::pair<double, double>> points);
  double at(double distance) const;
  bool empty() const { return points_.empty(); }
  const std::vector<std::pair<double, double>>& points() const { return points_; }

 private:
  std::vector<std::pair<double, double>> points_;
};

struct Road {
  Profile grade;
  Profile bank;
};

// Gravity (m/s^2) in the yaw frame (x forward along the road, y left, z normal to the road).
std::array<double, 3> gravity_in_road_frame(double grade, double bank);

}  // namespace dynid::sim
