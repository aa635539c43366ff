#include "dynid/car/ecef.hpp"

#include <cmath>

namespace dynid::car {
namespace {

constexpr double kA = 6378137.0;               // WGS84 semi-major axis (m)
constexpr double kF = 1.0 / 298.257223563;     // flattening
constexpr double kB = kA * (1.0 - kF);         // semi-minor axis
constexpr double kE2 = kF * (2.0 - kF);        // first eccentricity squared
constexpr double kEp2 = (kA * kA - kB * kB) / (kB * kB);  // second eccentricity squared

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

Vec3 wgs84_up(const Vec3& p) {
  const double r = std::hypot(p[0], p[1]);
  const double theta = std::atan2(p[2] * kA, r * kB);
  const double s = std::sin(theta), c = std::cos(theta);
  const double lat = std::atan2(p[2] + kEp2 * kB * s * s * s, r - kE2 * kA * c * c * c);
  const double lon = std::atan2(p[1], p[0]);
  return {std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)};
}

std::optional<double> path_grade(const Vec3& position, const Vec3& velocity, double min_horizontal) {
  const Vec3 up = wgs84_up(position);
  const double vertical = dot(velocity, up);
  const Vec3 h{velocity[0] - vertical * up[0], velocity[1] - vertical * up[1], velocity[2] - vertical * up[2]};
  const double horizontal = std::sqrt(dot(h, h));
  if (!(horizontal >= min_horizontal)) return std::nullopt;
  return std::atan2(vertical, horizontal);
}

double path_speed(const Vec3& velocity) { return std::sqrt(dot(velocity, velocity)); }

}  // namespace dynid::car
