// Vehicle profiles: the committed ones load and mean what they say; every kind of error names
// the file, the key and the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <dynid/error.hpp>

#include "car_test_support.hpp"
#include "dynid/model/channel_catalogue.hpp"
#include "dynid/car/units.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {
namespace {

using test::profile_path;

const ChannelMapping& mapping(const VehicleProfile& p, const std::string& channel) {
  for (const auto& m : p.channels)
    if (m.channel == channel) return m;
  throw std::runtime_error("no mapping for " + channel);
}

TEST(CarProfile, TestcarProfileMapsTheSimulatorsDbc) {
  const VehicleProfile p = load_vehicle_profile(profile_path("testcar.toml"));
  EXPECT_EQ(p.vehicle, "dynid-testcar");
  EXPECT_EQ(p.rate_hz, 100.0);
  EXPECT_EQ(p.chunk_rows, 100U);
  EXPECT_TRUE(p.interfaces.empty());
  EXPECT_EQ(p.spool_directory, "/var/lib/dynid/spool/dynid-testcar");
  for (const auto& m : p.channels) EXPECT_EQ(m.unit, *model::channel_unit(m.channel)) << m.channel;
  // km/h -> m/s; deg/s -> rad/s; steering wheel deg -> road wheel rad over the ratio of 16.
  const auto& vx = mapping(p, "vx");
  EXPECT_DOUBLE_EQ(vx.value({0, 0, 0, 36.0}), 10.0);  // VehSpeed is signal 3 of ESP_Dynamics
  const auto& steer = mapping(p, "steer");
  EXPECT_NEAR(steer.value({160.0, 0, 0}), 10.0 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_NEAR(mapping(p, "brake_pressure").value({12.5, 0}), 12.5e5, 1e-9);
  EXPECT_NEAR(mapping(p, "susp_travel_fl").value({25.0, 0, 0, 0}), 0.025, 1e-15);
  EXPECT_EQ(mapping(p, "gear").unit, "-");
  // The announcement carries channels, units and models with the merged constants.
  const auto a = p.announcement("run-1");
  EXPECT_EQ(a.channels.size(), p.channels.size());
  EXPECT_EQ(a.channels[0].name, "vx");
  EXPECT_EQ(a.channels[0].unit, "m/s");
  ASSERT_FALSE(a.models.empty());
  EXPECT_EQ(a.models[0].model, "longitudinal_wheel");
  EXPECT_EQ(a.models[0].constants.at("wheel_radius"), 0.30);
  EXPECT_EQ(a.models[0].effects, std::vector<std::string>{"road_grade"});
  EXPECT_NO_THROW(a.validate());
}

TEST(CarProfile, Rav4ProfileMeansWheelSpeedsAndScalesTheSteeringWheel) {
  DYNID_REQUIRE_RAV4_DATA();
  const VehicleProfile p = load_vehicle_profile(profile_path("rav4.toml"));
  EXPECT_EQ(p.interfaces, std::vector<std::string>{"can0"});
  EXPECT_FALSE(p.accepts_interface("can1"));
  EXPECT_EQ(p.chunk_rows, 50U);
  const auto& vx = mapping(p, "vx");
  ASSERT_EQ(vx.inputs.size(), 4U);
  EXPECT_EQ(vx.combine, Combine::Mean);
  // WHEEL_SPEEDS signal order in the DBC: FR, FL, RR, RL (km/h).
  EXPECT_NEAR(vx.value({36.0, 72.0, 36.0, 72.0}), 15.0, 1e-12);
  const auto& steer = mapping(p, "steer");
  ASSERT_EQ(steer.inputs.size(), 2U);
  // STEER_ANGLE + STEER_FRACTION (deg) / 16.88 in rad.
  EXPECT_NEAR(steer.value({15.0, 0.4, 0.0}), (15.4 / 16.88) * std::numbers::pi / 180.0, 1e-15);
  EXPECT_NEAR(mapping(p, "engine_speed").value({3000.0}), 3000.0 * 2.0 * std::numbers::pi / 60.0, 1e-12);
  EXPECT_NEAR(mapping(p, "yaw_rate").value({0, 10.0, 0}), 10.0 * std::numbers::pi / 180.0, 1e-15);
}

TEST(CarProfile, UnitTableConvertsOnlyWithinOneQuantity) {
  EXPECT_NEAR(conversion("km/h", "m/s")->apply(36.0), 10.0, 1e-15);
  EXPECT_NEAR(conversion("rpm", "rad/s")->apply(60.0), 2.0 * std::numbers::pi, 1e-15);
  EXPECT_NEAR(conversion("bar", "Pa")->apply(2.0), 2e5, 1e-9);
  EXPECT_NEAR(conversion("g", "m/s^2")->apply(1.0), 9.80665, 1e-15);
  EXPECT_NEAR(conversion("%", "-")->apply(50.0), 0.5, 1e-15);
  EXPECT_NEAR(conversion("Nm", "N m")->apply(7.0), 7.0, 0.0);
  EXPECT_FALSE(conversion("km/h", "rad/s"));
  EXPECT_FALSE(conversion("furlong", "m"));
  EXPECT_EQ(model::channel_unit("d_yaw_rate"), "rad/s^2");
  EXPECT_EQ(model::channel_unit("d_susp_travel_fl"), "m/s");
  EXPECT_FALSE(model::channel_unit("speed"));
}

// A valid test-car profile to break one piece at a time. Its nominal file lives beside the real
// profiles so the DBC path resolves like theirs.
const std::string kGood = R"(
[vehicle]
id = "t"
dbc = "../dbc/dynid_testcar.dbc"
[grid]
rate_hz = 100.0
chunk_seconds = 0.5
[spool]
directory = "spool"
max_bytes = 1000000
[constants]
steering_ratio = 16.0
a = 1.0
b = 1.5
[[models]]
name = "lateral_bicycle"
[[channels]]
name = "vx"
message = "ESP_WheelSpeeds"
signals = ["WhlSpd_FL", "WhlSpd_FR", "WhlSpd_RL", "WhlSpd_RR"]
combine = "mean"
[[channels]]
name = "steer"
message = "SAS_Steering"
signal = "SteerWheelAngle"
divide_by = "steering_ratio"
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  if (pos == std::string::npos) throw std::runtime_error("test text has no '" + from + "'");
  return text.replace(pos, from.size(), to);
}

// The message of the InputError that parsing `text` throws ("" when it does not throw).
std::string error_of(const std::string& text) {
  try {
    (void)parse_vehicle_profile(text, profile_path("broken.toml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& text, const std::string& where, const std::string& key,
                  const std::string& reason) {
  const std::string msg = error_of(text);
  ASSERT_FALSE(msg.empty()) << "no error for key " << key;
  EXPECT_NE(msg.find(profile_path("broken.toml").string() + where), std::string::npos) << msg;
  EXPECT_NE(msg.find(": " + key + ": "), std::string::npos) << msg;
  EXPECT_NE(msg.find(reason), std::string::npos) << msg;
}

TEST(CarProfile, TheBaseOfTheErrorCasesIsValid) {
  const VehicleProfile p = parse_vehicle_profile(kGood, profile_path("broken.toml"));
  EXPECT_EQ(p.chunk_rows, 50U);
  EXPECT_EQ(p.spool_directory, profile_path("spool"));
  EXPECT_EQ(p.models.at(0).constants.at("a"), 1.0);
}

TEST(CarProfile, UnknownDbcSignalAndMessage) {
  expect_error(replace(kGood, "\"WhlSpd_RR\"", "\"WhlSpd_XX\""), ":20:", "channels[0].signals",
               "unknown DBC signal 'WhlSpd_XX' in message 'ESP_WheelSpeeds' of dynid_testcar.dbc");
  expect_error(replace(kGood, "\"SAS_Steering\"", "\"SAS_Steer\""), ":24:", "channels[1].message",
               "unknown DBC message 'SAS_Steer'");
}

TEST(CarProfile, UnknownAndDuplicateChannel) {
  expect_error(replace(kGood, "name = \"steer\"", "name = \"steering\""), ":23:", "channels[1].name",
               "unknown channel 'steering' (see docs/CHANNELS.md)");
  expect_error(replace(kGood, "name = \"steer\"", "name = \"vx\""), ":23:", "channels[1].name",
               "duplicate channel 'vx'");
}

TEST(CarProfile, MissingAndUnconvertibleUnits) {
  // BrakePedalPressed has no unit in the DBC; brake_pressure needs Pa.
  const std::string brake = kGood + "[[channels]]\nname = \"brake_pressure\"\nmessage = \"BRK_Status\"\n"
                                    "signal = \"BrakePedalPressed\"\n";
  expect_error(brake, ":30:", "channels[2].signal",
               "missing unit: signal BRK_Status.BrakePedalPressed has no unit in the DBC and channel "
               "'brake_pressure' needs 'Pa'");
  // ... unless the profile says what it is.
  EXPECT_NO_THROW(parse_vehicle_profile(brake + "dbc_unit = \"bar\"\n", profile_path("broken.toml")));
  const auto explicit_factor = parse_vehicle_profile(brake + "factor = 2.0e5\n", profile_path("broken.toml"));
  EXPECT_EQ(explicit_factor.channels[2].value({0.0, 1.0}), 2.0e5);
  // Wheel speeds (km/h) cannot become a yaw rate (rad/s).
  expect_error(replace(kGood, "name = \"vx\"", "name = \"yaw_rate\""), ":20:", "channels[0].signals",
               "cannot convert signal ESP_WheelSpeeds.WhlSpd_FL from 'km/h' to 'rad/s' (channel 'yaw_rate')");
}

TEST(CarProfile, BadTypesAndValues) {
  expect_error(replace(kGood, "rate_hz = 100.0", "rate_hz = \"fast\""), ":6:", "grid.rate_hz",
               "expected a number");
  expect_error(replace(kGood, "rate_hz = 100.0", "rate_hz = -5.0"), ":6:", "grid.rate_hz", "must be > 0");
  expect_error(replace(kGood, "chunk_seconds = 0.5", "chunk_seconds = 0.123"), ":7:", "grid.chunk_seconds",
               "must be a whole number (>= 1) of grid periods");
  expect_error(replace(kGood, "max_bytes = 1000000", "max_bytes = 1.5"), ":10:", "spool.max_bytes",
               "expected an integer (bytes)");
  expect_error(replace(kGood, "combine = \"mean\"", "combine = \"median\""), ":21:", "channels[0].combine",
               "expected \"sum\" or \"mean\"");
  expect_error(replace(kGood, "combine = \"mean\"", "sign = 2"), ":21:", "channels[0].sign", "expected 1 or -1");
  expect_error(replace(kGood, "combine = \"mean\"", "interpolation = \"spline\""), ":21:",
               "channels[0].interpolation", "expected \"linear\" or \"cubic\"");
  expect_error(replace(kGood, "signals = [\"WhlSpd_FL\"", "signals = [3"), ":20:", "channels[0].signals[0]",
               "expected a string");
  expect_error(replace(kGood, "id = \"t\"", "id = 7"), ":3:", "vehicle.id", "expected a string");
  expect_error(replace(kGood, "id = \"t\"\n", ""), "", "vehicle.id", "missing key");
  expect_error(replace(kGood, "combine = \"mean\"", "combin = \"mean\""), ":21:", "channels[0].combin",
               "unknown key");
  expect_error(replace(kGood, "a = 1.0", "a = nan"), ":13:", "constants.a", "must be finite");
}

TEST(CarProfile, AChannelIsInterpolatedLinearlyUnlessItsMappingSaysCubic) {
  const auto linear = parse_vehicle_profile(kGood, profile_path("broken.toml"));
  EXPECT_EQ(linear.channels[0].interpolation, Interpolation::kLinear);
  const auto cubic = parse_vehicle_profile(replace(kGood, "combine = \"mean\"", "combine = \"mean\"\ninterpolation = \"cubic\""),
                                           profile_path("broken.toml"));
  EXPECT_EQ(cubic.channels[0].interpolation, Interpolation::kCubic);
  EXPECT_EQ(cubic.channels[1].interpolation, Interpolation::kLinear);
}

// Issue 36, item 3: a channel given as a constant in its SI unit: its value only, within the
// channel's physical range.
TEST(CarProfile, AChannelGivenAsAConstantHasItsValueOnly) {
  const std::string with = kGood + "[[channels]]\nname = \"gear_ratio\"\nconstant = 3.5\n";
  const VehicleProfile p = parse_vehicle_profile(with, profile_path("broken.toml"));
  const ChannelMapping& gear = mapping(p, "gear_ratio");
  ASSERT_TRUE(gear.constant.has_value());
  EXPECT_EQ(*gear.constant, 3.5);
  EXPECT_EQ(gear.unit, "-");
  EXPECT_TRUE(gear.inputs.empty());
  EXPECT_FALSE(mapping(p, "vx").constant.has_value());
  expect_error(replace(with, "constant = 3.5", "constant = 3.5\nmessage = \"SAS_Steering\""),
               ":30:", "channels[2].message", "unknown key");
  expect_error(replace(with, "constant = 3.5", "constant = \"3.5\""),
               ":29:", "channels[2].constant", "expected a number");
  expect_error(replace(kGood + "[[channels]]\nname = \"vy\"\nconstant = 3.5\n", "constant = 3.5",
                       "constant = 500"),
               ":29:", "channels[2].constant",
               "channel 'vy' cannot be 500 m/s (its physical range is -120 to 120 m/s)");
}

TEST(CarProfile, ConstantsAndModels) {
  expect_error(replace(kGood, "divide_by = \"steering_ratio\"", "divide_by = \"ratio\""), ":26:",
               "channels[1].divide_by", "no constant 'ratio' in [constants]");
  expect_error(replace(kGood, "divide_by = \"steering_ratio\"", "divide_by = 0"), ":26:",
               "channels[1].divide_by", "must not be 0");
  expect_error(replace(kGood, "name = \"lateral_bicycle\"", "name = \"bicycle\""), ":16:", "models[0].name",
               "bicycle");
  // lateral_bicycle needs b: the registry's reason is carried through.
  expect_error(replace(kGood, "b = 1.5\n", ""), ":15:", "models[0].name", "'b'");
}

// A constant nobody reads loads, but is said: a misspelling, or a channel given as a constant
// (a manual car's gear ratio), which would otherwise be ignored without a word.
TEST(CarProfile, AConstantNoModelReadsIsAWarningNamingItsLine) {
  EXPECT_TRUE(parse_vehicle_profile(kGood, profile_path("broken.toml")).warnings.empty())
      << "steering_ratio is a gain term's, a and b the bicycle's";
  const std::string text =
      replace(replace(kGood, "b = 1.5\n", "b = 1.5\ngear_ratio = 3.5\nmas = 1500.0\n"),
              "name = \"lateral_bicycle\"\n",
              "name = \"lateral_bicycle\"\nconstants = { min_sped = 2.0, min_speed = 2.0 }\n");
  const VehicleProfile p = parse_vehicle_profile(text, profile_path("broken.toml"));
  ASSERT_EQ(p.warnings.size(), 3U) << ::testing::PrintToString(p.warnings);
  const std::string file = profile_path("broken.toml").string();
  EXPECT_EQ(p.warnings[0].rfind(file + ":19:", 0), 0U) << p.warnings[0];
  EXPECT_NE(p.warnings[0].find("models[0].constants.min_sped: read by no constant of model "
                               "'lateral_bicycle'"),
            std::string::npos)
      << p.warnings[0];
  EXPECT_EQ(p.warnings[1].rfind(file + ":15:", 0), 0U) << p.warnings[1];
  EXPECT_NE(p.warnings[1].find("constants.gear_ratio: 'gear_ratio' is a channel, not a constant"),
            std::string::npos)
      << p.warnings[1];
  EXPECT_NE(p.warnings[2].find("constants.mas: read by no model of this profile"),
            std::string::npos)
      << p.warnings[2];
}

// Issue 16 item 5: [preprocessing] sets the server's processing per vehicle; absent keys keep
// today's values (ingest::Preprocessing's defaults), and every run's announcement carries it.
TEST(CarProfile, PreprocessingPerVehicleWithTodaysDefaults) {
  const VehicleProfile plain = parse_vehicle_profile(kGood, profile_path("broken.toml"));
  const ingest::Preprocessing defaults;
  EXPECT_EQ(plain.preprocessing.butterworth_order, defaults.butterworth_order);
  EXPECT_EQ(plain.preprocessing.odmf, defaults.odmf);
  EXPECT_EQ(plain.preprocessing.cutoff_hz, 0.0);
  EXPECT_TRUE(plain.preprocessing.channel_noise.empty());

  const std::string set = kGood + "[preprocessing]\nbutterworth_order = 4\ncut_off_hz = 6.5\nodmf = 5\n"
                                  "noise = { vx = 0.02, steer = 0.001 }\n";
  const VehicleProfile p = parse_vehicle_profile(set, profile_path("broken.toml"));
  EXPECT_EQ(p.preprocessing.butterworth_order, 4);
  EXPECT_EQ(p.preprocessing.cutoff_hz, 6.5);
  EXPECT_EQ(p.preprocessing.odmf, 5);
  EXPECT_EQ(p.preprocessing.channel_noise.at("steer"), 0.001);
  const ingest::RunAnnouncement a = p.announcement("run-1");
  EXPECT_EQ(a.preprocessing.odmf, 5);
  EXPECT_EQ(a.preprocessing.channel_noise, p.preprocessing.channel_noise);
  EXPECT_NO_THROW(a.validate());

  const std::string base = kGood + "[preprocessing]\n";
  expect_error(base + "odmf = 0\n", ":28:", "preprocessing.odmf", "must be within 1..1000");
  expect_error(base + "odmf = 2.5\n", ":28:", "preprocessing.odmf", "expected an integer");
  expect_error(base + "butterworth_order = 9\n", ":28:", "preprocessing.butterworth_order", "1..8");
  expect_error(base + "cut_off_hz = 60.0\n", ":28:", "preprocessing.cut_off_hz", "Nyquist frequency");
  expect_error(base + "noise = { ax = 0.1 }\n", ":28:", "preprocessing.noise.ax",
               "'ax' is not a channel of this profile");
  expect_error(base + "noise = { vx = -0.1 }\n", ":28:", "preprocessing.noise.vx", "must be > 0");
  expect_error(base + "cutoff = 5.0\n", ":28:", "preprocessing.cutoff", "unknown key");
}

// A DBC as production files are: messages the profile does not use carry an ambiguous signal
// name, a layout error, a name that two messages share. The profile that does not use them
// loads; one that selects them is refused with the reason and the DBC's lines.
const std::string kWildDbc =
    "BO_ 100 WHEELS: 8 X\n"
    " SG_ SPEED : 0|16@1+ (0.01,0) [0|0] \"m/s\" X\n"
    "BO_ 200 RADAR: 8 X // the radar repeats CHECKSUM in each group\n"
    " SG_ MUX M : 0|1@1+ (1,0) [0|0] \"\" X\n"
    " SG_ CHECKSUM m0 : 56|8@1+ (1,0) [0|0] \"\" X\n"
    " SG_ CHECKSUM m1 : 56|8@1+ (1,0) [0|0] \"\" X\n"
    " SG_ RANGE_RATE m0 : 8|16@1- (0.01,0) [0|0] \"m/s\" X\n"
    "BO_ 300 BROKEN: 8 X\n"
    " SG_ LONG : 0|65@1+ (1,0) [0|0] \"m/s\" X\n"
    "BO_ 400 TWIN: 8 X\n"
    " SG_ V : 0|16@1+ (0.01,0) [0|0] \"m/s\" X\n"
    "BO_ 401 TWIN: 8 X\n"
    " SG_ V : 0|16@1+ (0.01,0) [0|0] \"m/s\" X\n";

std::string wild_profile(const std::filesystem::path& dbc, const std::string& message,
                         const std::string& signal) {
  return "[vehicle]\nid = \"t\"\ndbc = \"" + dbc.string() +
         "\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 0.5\n[spool]\ndirectory = \"spool\"\n"
         "max_bytes = 1000000\n[[channels]]\nname = \"vx\"\nmessage = \"" +
         message + "\"\nsignal = \"" + signal + "\"\n";
}

TEST(CarProfile, AWildDbcServesTheMessagesAProfileCanUse) {
  const test::ScratchDir dir("wild-dbc");
  const auto dbc = dir.path() / "wild.dbc";
  std::ofstream(dbc) << kWildDbc;
  const VehicleProfile p =
      parse_vehicle_profile(wild_profile(dbc, "WHEELS", "SPEED"), profile_path("broken.toml"));
  EXPECT_EQ(p.channels.at(0).dbc_message->id, 100U);
  EXPECT_EQ(p.dbc->warnings.size(),
            3U);  // the ambiguous name, the unusable message, the shared name
  const VehicleProfile radar =
      parse_vehicle_profile(wild_profile(dbc, "RADAR", "RANGE_RATE"), profile_path("broken.toml"));
  EXPECT_EQ(radar.channels.at(0).inputs.at(0).index, 3U);

  expect_error(
      wild_profile(dbc, "RADAR", "CHECKSUM"), ":13:", "channels[0].signal",
      "DBC signal 'CHECKSUM' of message 'RADAR' is ambiguous: wild.dbc defines it 2 times, "
      "at lines 5 and 6 (under different multiplexer values)");
  expect_error(
      wild_profile(dbc, "BROKEN", "LONG"), ":12:", "channels[0].message",
      "DBC message 'BROKEN' cannot be decoded: wild.dbc:9: SG_ 'LONG': length 65 is outside "
      "1..64 bits");
  expect_error(
      wild_profile(dbc, "TWIN", "V"), ":12:", "channels[0].message",
      "DBC message name 'TWIN' is ambiguous: wild.dbc has 2 messages of that name, ids 0x190 "
      "(line 10) and 0x191 (line 12)");
}

TEST(CarProfile, SyntaxAndFileErrors) {
  expect_error(replace(kGood, "[grid]", "[grid"), ":5:", "TOML syntax", "");
  expect_error(replace(kGood, "dynid_testcar.dbc", "nope.dbc"), ":4:", "vehicle.dbc",
               "cannot read the DBC");
  const std::string msg = [] {
    try {
      (void)load_vehicle_profile(profile_path("does-not-exist.toml"));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_NE(msg.find("does-not-exist.toml: vehicle profile: no such file"), std::string::npos) << msg;
}

}  // namespace
}  // namespace dynid::car
