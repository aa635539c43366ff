// dynid-car --check-profile (client/car/profile_check.hpp): before anything is sent, which of the
// profile's models can run and exactly why not; with a log, each channel's rate and health and
// which models the log can judge. The test car's profile as shipped, one without the optical
// sensor's vy, and one whose ax is held at -0.57 m/s^2 (a stuck accelerometer, made by the
// profile's own conversion), each on a simulated run's CAN log.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>

#include "client_fixture.hpp"

namespace dynid::car {
namespace {

using namespace testing;
using namespace std::chrono_literals;

std::string profile_text() {
  std::string text = read_text(testcar_profile());
  const std::string dbc = "dbc = \"../dbc/dynid_testcar.dbc\"";
  text.replace(
      text.find(dbc), dbc.size(),
      "dbc = \"" + (testcar_profile().parent_path() / "../dbc/dynid_testcar.dbc").string() + "\"");
  return text;
}

std::filesystem::path write_profile(const ScratchDir& scratch, const std::string& name,
                                    const std::string& text) {
  const auto path = scratch.path() / name;
  std::ofstream(path) << text;
  return path;
}

struct Checked {
  int status = -1;
  std::string output;
};

Checked check(const ScratchDir& scratch, const std::filesystem::path& profile,
              const std::string& log = "") {
  std::vector<std::string> args{DYNID_CAR, "--profile", profile.string(), "--check-profile"};
  if (!log.empty()) args.insert(args.end(), {"--replay", log});
  const auto out = scratch.path() / "check.out";
  Child car(args, out);
  Checked c;
  c.status = car.wait(60s).value_or(-1);
  c.output = read_text(out);
  return c;
}

TEST(CheckProfile, TheShippedProfileRunsEveryModelAndNamesEachChannelsRate) {
  ScratchDir scratch("check-profile-shipped");
  const Checked alone = check(scratch, testcar_profile());
  EXPECT_EQ(alone.status, 0) << alone.output;
  EXPECT_NE(alone.output.find("lateral_bicycle: can run"), std::string::npos) << alone.output;
  EXPECT_NE(alone.output.find("every model can run"), std::string::npos) << alone.output;
  const auto run_dir = simulated_run("step_steer", scratch);
  const Checked with_log = check(scratch, testcar_profile(), (run_dir / "can.log").string());
  EXPECT_EQ(with_log.status, 0) << with_log.output;
  // ESP_Dynamics is sent at 100 Hz on the test car.
  EXPECT_TRUE(std::regex_search(
      with_log.output,
      std::regex(R"(  ax \[m/s\^2\] from ESP_Dynamics\.LongAccel: (99\.|100\.)[0-9] Hz)")))
      << with_log.output;
  EXPECT_NE(with_log.output.find("models on this log:"), std::string::npos) << with_log.output;
  // A check sends and writes nothing: asked to write chunks too, it refuses at once.
  const auto out = scratch.path() / "both.out";
  Child both({DYNID_CAR, "--profile", testcar_profile().string(), "--check-profile", "--chunks-out",
              (scratch.path() / "x.chunks").string()},
             out);
  EXPECT_EQ(both.wait(60s).value_or(-1), 1);
  EXPECT_NE(read_text(out).find("--check-profile sends and writes nothing"), std::string::npos)
      << read_text(out);
  EXPECT_FALSE(std::filesystem::exists(scratch.path() / "x.chunks"));
}

TEST(CheckProfile, AModelWithoutItsChannelIsNamedWithTheChannelAndExitIsOne) {
  ScratchDir scratch("check-profile-no-vy");
  std::string text = profile_text();
  const std::string vy =
      "[[channels]]\nname = \"vy\"\nmessage = \"TI_Optical\"\nsignal = \"VelLat\"\n";
  ASSERT_NE(text.find(vy), std::string::npos);
  text.erase(text.find(vy), vy.size());
  const Checked c = check(scratch, write_profile(scratch, "no-vy.toml", text));
  EXPECT_EQ(c.status, 1) << c.output;
  EXPECT_TRUE(std::regex_search(
      c.output,
      std::regex("lateral_bicycle: cannot run: models\\[1\\] 'lateral_bicycle' needs [^\\n]*vy")))
      << c.output;
  EXPECT_NE(c.output.find("kinematic_longitudinal: can run"), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("of 13 models cannot run"), std::string::npos) << c.output;
}

TEST(CheckProfile, AStuckAccelerometerIsNamedAndTheModelsReadingItCannotBeJudged) {
  ScratchDir scratch("check-profile-stuck-ax");
  std::string text = profile_text();
  const std::string ax = "name = \"ax\"\nmessage = \"ESP_Dynamics\"\nsignal = \"LongAccel\"\n";
  ASSERT_NE(text.find(ax), std::string::npos);
  text.insert(text.find(ax) + ax.size(), "factor = 0.0\noffset = -0.57\n");
  const auto run_dir = simulated_run("step_steer", scratch);
  const Checked c =
      check(scratch, write_profile(scratch, "stuck-ax.toml", text), (run_dir / "can.log").string());
  EXPECT_EQ(c.status, 1) << c.output;
  EXPECT_NE(c.output.find("`ax` is constant at -0.57 m/s^2"), std::string::npos) << c.output;
  EXPECT_TRUE(std::regex_search(
      c.output, std::regex("kinematic_longitudinal: cannot run: not identified: `ax` is constant")))
      << c.output;
  EXPECT_NE(c.output.find("lateral_bicycle: can run"), std::string::npos) << c.output;
}

}  // namespace
}  // namespace dynid::car
