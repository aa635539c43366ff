// A GNSS/INS pose in ECEF as an auxiliary source (issue 17): the road grade derived from its
// velocity against the WGS84 normal, checked against poses built from known latitude, longitude,
// height and slope, and on the RAV4 recorder's pose.csv against the normal computed another way
// (the ellipsoid's gradient); the profile's ECEF keys refused with the key named when wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <dynid/error.hpp>

#include "car_test_support.hpp"
#include "dynid/car/auxiliary.hpp"
#include "dynid/car/ecef.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {
namespace {

constexpr double kA = 6378137.0, kF = 1.0 / 298.257223563, kE2 = kF * (2.0 - kF);
constexpr double kDeg = std::numbers::pi / 180.0;

// Geodetic latitude, longitude (rad) and height (m) to ECEF: the forward transform, exact.
Vec3 ecef_of(double lat, double lon, double h) {
  const double n = kA / std::sqrt(1.0 - kE2 * std::sin(lat) * std::sin(lat));
  return {(n + h) * std::cos(lat) * std::cos(lon), (n + h) * std::cos(lat) * std::sin(lon),
          (n * (1.0 - kE2) + h) * std::sin(lat)};
}

TEST(GnssPose, TheGradeOfAPathOfKnownSlopeAnywhereOnEarth) {
  for (const double lat : {-60.0, -12.5, 0.0, 37.4, 48.8, 71.0})
    for (const double lon : {-122.1, 2.35, 139.7})
      for (const double slope : {-0.12, -0.01, 0.0, 0.004, 0.08}) {
        const double phi = lat * kDeg, lambda = lon * kDeg;
        const Vec3 up{std::cos(phi) * std::cos(lambda), std::cos(phi) * std::sin(lambda), std::sin(phi)};
        const Vec3 north{-std::sin(phi) * std::cos(lambda), -std::sin(phi) * std::sin(lambda), std::cos(phi)};
        const Vec3 east{-std::sin(lambda), std::cos(lambda), 0.0};
        // 22 m/s heading 30 degrees east of north, climbing at `slope`.
        Vec3 v;
        for (int i = 0; i < 3; ++i)
          v[i] = 22.0 * (std::cos(slope) * (std::cos(30 * kDeg) * north[i] + std::sin(30 * kDeg) * east[i]) +
                         std::sin(slope) * up[i]);
        const auto grade = path_grade(ecef_of(phi, lambda, 312.0), v);
        ASSERT_TRUE(grade.has_value());
        EXPECT_NEAR(*grade, slope, 1e-9) << "lat " << lat << " lon " << lon;
        EXPECT_NEAR(path_speed(v), 22.0, 1e-12);
      }
}

TEST(GnssPose, ACarAtRestHasNoGrade) {
  const Vec3 p = ecef_of(45 * kDeg, 5 * kDeg, 200.0);
  EXPECT_FALSE(path_grade(p, {0.3, -0.2, 0.4}).has_value());
  EXPECT_FALSE(path_grade(p, {0.0, 0.0, 0.0}).has_value());
}

// The normal as the gradient of x^2/a^2 + y^2/a^2 + z^2/b^2 at the point (another method; at
// road heights it differs from the geodetic normal by ~1e-7 rad).
Vec3 gradient_up(const Vec3& p) {
  const double b = kA * (1.0 - kF);
  Vec3 g{p[0] / (kA * kA), p[1] / (kA * kA), p[2] / (b * b)};
  const double n = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  return {g[0] / n, g[1] / n, g[2] / n};
}

TEST(GnssPose, TheRav4RecorderPoseGivesTheRoadGradeChannel) {
  DYNID_REQUIRE_RAV4_DATA();
  const VehicleProfile declared = load_vehicle_profile(test::profile_path("rav4.toml"));
  const auto pose = test::rav4_data_dir() / "pose.csv";
  const RunSources run = prepare_sources(declared, {{"gnss_pose", pose}}, nullptr);
  std::size_t column = run.profile.channels.size();
  for (std::size_t c = 0; c < run.profile.channels.size(); ++c)
    if (run.profile.channels[c].channel == "road_grade") column = c;
  ASSERT_LT(column, run.profile.channels.size()) << "the run has a road_grade channel";

  // The reference: every row of pose.csv moving at >= 1 m/s horizontally.
  std::ifstream in(pose);
  std::string line;
  std::getline(in, line);
  std::vector<std::pair<double, double>> expected;  // time, grade
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::array<double, 7> v{};
    for (auto& x : v) {
      std::string cell;
      std::getline(cells, cell, ',');
      x = std::stod(cell);
    }
    const Vec3 up = gradient_up({v[1], v[2], v[3]});
    const double vertical = v[4] * up[0] + v[5] * up[1] + v[6] * up[2];
    const double horizontal = std::sqrt(std::max(0.0, v[4] * v[4] + v[5] * v[5] + v[6] * v[6] - vertical * vertical));
    if (horizontal >= 1.0) expected.emplace_back(v[0], std::atan2(vertical, horizontal));
  }
  std::vector<AuxiliarySample> grades;
  for (const auto& s : run.samples)
    if (s.channel == column) grades.push_back(s);
  ASSERT_EQ(grades.size(), expected.size());
  ASSERT_GT(grades.size(), 1000u);
  double worst = 0.0, lowest = 0.0, highest = 0.0;
  for (std::size_t i = 0; i < grades.size(); ++i) {
    EXPECT_DOUBLE_EQ(grades[i].time, expected[i].first);
    worst = std::max(worst, std::abs(grades[i].value - expected[i].second));
    lowest = std::min(lowest, grades[i].value);
    highest = std::max(highest, grades[i].value);
  }
  EXPECT_LT(worst, 1e-6) << "rad";
  EXPECT_LT(lowest, -0.01) << "the segment runs downhill and uphill";
  EXPECT_GT(highest, 0.01);
}

std::string profile_error(const std::string& source) {
  const std::string text =
      "[vehicle]\nid = \"gnss-car\"\ndbc = \"" + std::string(DYNID_SOURCE_DIR) +
      "/deploy/dbc/dynid_testcar.dbc\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 1.0\n[spool]\n"
      "directory = \"spool\"\nmax_bytes = 1000000\n[[channels]]\nname = \"vx\"\nmessage = \"ESP_Dynamics\"\n"
      "signal = \"VehSpeed\"\n[[sources]]\nname = \"gnss\"\ntype = \"csv\"\ntime_column = \"t\"\ntime_unit = \"s\"\n"
      "clock = { offset = 0.0 }\n" + source;
  try {
    (void)parse_vehicle_profile(text, "gnss.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

TEST(GnssPose, TheProfileSaysWhatIsWrongWithADerivedChannel) {
  const std::string ecef = "ecef = { position = [\"x\", \"y\", \"z\"], velocity = [\"vx\", \"vy\", \"vz\"] }\n";
  const std::string grade = "[[sources.channels]]\nderived = \"grade\"\nchannel = \"road_grade\"\n";
  EXPECT_EQ(profile_error(ecef + grade), "(accepted)");
  EXPECT_HAS(profile_error(grade), "ecef");
  EXPECT_HAS(profile_error(ecef + "[[sources.channels]]\nderived = \"slope\"\nchannel = \"road_grade\"\n"),
             "unknown derived quantity 'slope'");
  EXPECT_HAS(profile_error(ecef + "[[sources.channels]]\nderived = \"grade\"\nchannel = \"vx\"\nreplaces_bus = true\n"),
             "the grade is in rad, channel 'vx' in m/s");
  EXPECT_HAS(profile_error(ecef + "[[sources.channels]]\nderived = \"grade\"\ncolumn = \"g\"\nchannel = \"road_grade\"\n"),
             "no column and no unit");
  EXPECT_HAS(profile_error("ecef = { position = [\"x\", \"y\"], velocity = [\"vx\", \"vy\", \"vz\"] }\n" + grade),
             "ecef.position");
}

}  // namespace
}  // namespace dynid::car
