// The real RAV4 log decoded with its DBC equals comma.ai's own decode (reference/*.csv).
#include <gtest/gtest.h>

#include <cmath>
#include <dynid/can/candump.hpp>
#include <dynid/can/dbc.hpp>
#include <dynid/can/decoder.hpp>
#include <fstream>
#include <map>
#include <sstream>

#include "can_test_support.hpp"

namespace dynid::can {
namespace {

constexpr double kKphToMps = 1.0 / 3.6;  // comma's CV.KPH_TO_MS
constexpr double kTimeMatch = 1e-6;      // the log keeps microseconds, the CSV more digits

struct Row {
  double t = 0.0;
  std::vector<double> values;
};

std::vector<Row> read_csv(const std::filesystem::path& path, std::size_t columns) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string cell;
    Row r;
    std::getline(fields, cell, ',');
    r.t = std::stod(cell);
    while (std::getline(fields, cell, ',')) r.values.push_back(std::stod(cell));
    EXPECT_EQ(r.values.size(), columns) << path << ": " << line;
    rows.push_back(r);
  }
  return rows;
}

// Decoded series of the log, by what the reference files hold.
struct Series {
  std::vector<Row> wheels;    // FL, FR, RL, RR in m/s at each WHEEL_SPEEDS frame
  std::vector<Row> steering;  // STEER_ANGLE + STEER_FRACTION, deg
  std::vector<Row> speed;     // SPEED signal, m/s
  DecodeStats stats;
  std::size_t log_errors = 0;
  std::size_t frames = 0;
};

double value(const std::vector<DecodedSignal>& out, std::string_view name) {
  for (const DecodedSignal& d : out)
    if (d.signal->name == name) return d.value;
  ADD_FAILURE() << "signal " << name << " not decoded";
  return std::nan("");
}

Series decode_log(const Database& db, const std::filesystem::path& log) {
  Series s;
  CandumpReader reader(log);
  Decoder decoder(db);
  Frame f;
  std::vector<DecodedSignal> out;
  while (reader.next(f)) {
    ++s.frames;
    if (f.interface_name() != "can0") continue;  // bus 0: the powertrain DBC
    const DecodeResult r = decoder.decode(f, out);
    if (r.status != DecodeStatus::Ok) continue;
    const std::string& name = r.message->name;
    if (name == "WHEEL_SPEEDS")
      s.wheels.push_back({f.timestamp,
                          {value(out, "WHEEL_SPEED_FL") * kKphToMps,
                           value(out, "WHEEL_SPEED_FR") * kKphToMps,
                           value(out, "WHEEL_SPEED_RL") * kKphToMps,
                           value(out, "WHEEL_SPEED_RR") * kKphToMps}});
    else if (name == "STEER_ANGLE_SENSOR")
      s.steering.push_back({f.timestamp, {value(out, "STEER_ANGLE") + value(out, "STEER_FRACTION")}});
    else if (name == "SPEED")
      s.speed.push_back({f.timestamp, {value(out, "SPEED") * kKphToMps}});
  }
  s.stats = decoder.stats();
  s.log_errors = reader.error_count();
  return s;
}

// Every reference row has exactly one decoded row at the same time, with equal values.
void expect_same(const std::vector<Row>& ours, const std::vector<Row>& ref, const char* what) {
  ASSERT_EQ(ours.size(), ref.size()) << what;
  std::size_t mismatches = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    ASSERT_NEAR(ours[i].t, ref[i].t, kTimeMatch) << what << " row " << i;
    for (std::size_t c = 0; c < ref[i].values.size(); ++c)
      if (std::fabs(ours[i].values[c] - ref[i].values[c]) > 1e-9 && ++mismatches < 10)
        ADD_FAILURE() << what << " row " << i << " column " << c << ": ours "
                      << ours[i].values[c] << ", reference " << ref[i].values[c];
  }
  EXPECT_EQ(mismatches, 0U) << what;
}

class Rav4 : public ::testing::Test {
 protected:
  void SetUp() override {
    DYNID_REQUIRE_DIR(test::rav4_dir());
    db_ = parse_dbc_file(test::rav4_dir() / "toyota_rav4_2017_pt_generated.dbc");
    series_ = decode_log(db_, test::rav4_dir() / "rav4_2018-08-02_seg40.candump.log");
  }
  Database db_;
  Series series_;
};

TEST_F(Rav4, LogReadsWithoutErrors) {
  EXPECT_EQ(series_.frames, 98800U);  // the README's count
  EXPECT_EQ(series_.log_errors, 0U);
  EXPECT_EQ(series_.stats.frames, 53800U);  // can0
  EXPECT_GT(series_.stats.decoded, 0U);
  // 0x262 and 0x2E4 are 5 bytes in the DBC, padded to 8 in the log: decoded and counted.
  EXPECT_GT(series_.stats.length_mismatch, 0U);
  EXPECT_EQ(series_.stats.short_payload, 0U);
}

TEST_F(Rav4, WheelSpeedsEqualReference) {
  expect_same(series_.wheels, read_csv(test::rav4_dir() / "reference/wheel_speed.csv", 4),
              "wheel speeds");
}

TEST_F(Rav4, SteeringAngleEqualsReference) {
  expect_same(series_.steering, read_csv(test::rav4_dir() / "reference/steering_angle.csv", 1),
              "steering angle");
}

// reference/speed.csv is comma's vEgoRaw: the mean of the four wheel speeds at each
// WHEEL_SPEEDS frame (4974 rows; the SPEED message 0x0B4 comes only 2487 times).
TEST_F(Rav4, SpeedEqualsReference) {
  std::vector<Row> mean;
  for (const Row& w : series_.wheels)
    mean.push_back({w.t, {(w.values[0] + w.values[1] + w.values[2] + w.values[3]) / 4.0}});
  expect_same(mean, read_csv(test::rav4_dir() / "reference/speed.csv", 1), "speed");
}

// The SPEED signal itself has no reference file; it must follow the wheels (same car, same
// time) within 10 % (the speedometer reads about 6 % high on this car), which a wrong bit
// layout would not.
TEST_F(Rav4, SpeedSignalFollowsWheelSpeeds) {
  ASSERT_GT(series_.speed.size(), 2000U);
  std::size_t w = 0;
  for (const Row& s : series_.speed) {
    while (w + 1 < series_.wheels.size() && series_.wheels[w + 1].t <= s.t) ++w;
    const auto& v = series_.wheels[w].values;
    const double mean = (v[0] + v[1] + v[2] + v[3]) / 4.0;
    ASSERT_NEAR(s.values[0], mean, 0.10 * mean + 0.1) << "t=" << s.t;
  }
}

}  // namespace
}  // namespace dynid::can
