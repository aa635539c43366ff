#pragma once
// What a vehicle's path does locally, from a GNSS/INS pose in ECEF (WGS84: the frame GNSS
// receivers and INS give position and velocity in): the derived channels of an auxiliary source
// that declares ECEF columns (vehicle_profile.hpp, [[sources]] ecef; auxiliary_csv.hpp).
//
// Up is the WGS84 ellipsoid normal at the position (geodetic latitude by Bowring's formula,
// exact to well below a microradian at road heights), not the direction from the Earth's centre
// (they differ by up to 3.4 mrad, a third of a 1 % grade).
#include <array>
#include <optional>

namespace dynid::car {

using Vec3 = std::array<double, 3>;

/// The unit ellipsoid normal ("up") at an ECEF position (metres).
Vec3 wgs84_up(const Vec3& position);

/// The slope of the path (radians, > 0 uphill): atan2(velocity along up, its horizontal part).
/// None when the horizontal speed is below `min_horizontal` (m/s): a car at rest has no path.
std::optional<double> path_grade(const Vec3& position, const Vec3& velocity, double min_horizontal = 1.0);

/// The speed over ground (m/s): the norm of the velocity.
double path_speed(const Vec3& velocity);

}  // namespace dynid::car
