// (d) The dynid executable against a running server: `dynid estimates --vehicle V` prints the
// table (parameter, unit, value, std, relative std %, status; rows, sigma, cond, residual RMS),
// the other commands answer, and without a server it says so within its timeout.
#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

CommandResult dynid(const std::vector<std::string>& arguments) { return run_dynid(arguments); }

TEST(E2eCli, EstimatesTableAgainstRunningServer) {
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  const auto run = test_run("cli-car", "run-c", 41u);
  const auto chunks = cut_run(run, 8u);
  TestCar car("cli-car");
  ASSERT_TRUE(car.stream(run.announcement, chunks));
  const auto expected = references(offline(run, chunks).estimates());
  EstimateWatcher watcher("cli-car");
  ASSERT_TRUE(watcher.wait_for(expected, "run-c"));

  const auto table = dynid({"estimates", "--vehicle", "cli-car"});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  for (const std::string word : {"cli-car / longitudinal_wheel", "parameter", "unit", "value", "std",
                                 "rel.std%", "status", "mass", "kg", "identified", "rows ",
                                 "sigma", "cond", "residual RMS", "kinematic_longitudinal"})
    EXPECT_NE(table.out.find(word), std::string::npos) << "missing '" << word << "' in\n" << table.out;
  const std::string rows = "rows " + std::to_string(watcher.latest("run-c").at("longitudinal_wheel").rows);
  EXPECT_NE(table.out.find(rows), std::string::npos) << table.out;

  const auto json = dynid({"--json", "estimates", "--vehicle", "cli-car", "--model", "locked_driveline"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  EXPECT_EQ(json.out.rfind("{\"tables\":[{\"vehicle\":\"cli-car\",\"model\":\"locked_driveline\"", 0), 0u) << json.out;

  const auto vehicles = dynid({"vehicles"});
  EXPECT_EQ(vehicles.out, "cli-car\n") << vehicles.err;
  const auto runs = dynid({"runs", "--vehicle", "cli-car"});
  EXPECT_NE(runs.out.find("run-c"), std::string::npos) << runs.err;
  const auto watch = dynid({"watch", "--vehicle", "cli-car", "--seconds", "1.5"});
  EXPECT_EQ(watch.exit_code, 0) << watch.err;
  EXPECT_NE(watch.out.find("cli-car / locked_driveline"), std::string::npos) << watch.out;
  const auto unknown = dynid({"estimates", "--vehicle", "nobody"});
  EXPECT_EQ(unknown.exit_code, 3);
  EXPECT_NE(unknown.err.find("unknown vehicle"), std::string::npos) << unknown.err;
}

TEST(E2eCli, SaysSoWhenNoServerAnswers) {
  std::vector<std::string> argv{DYNID_CLI_EXE, "--cyclone-config", loopback_config(), "--domain",
                                std::to_string(kDomain + 1), "--timeout", "1", "vehicles"};
  const auto result = run_command(argv, 10s);
  EXPECT_EQ(result.exit_code, 5);
  EXPECT_NE(result.err.find("no dynid-server found within 1000 ms"), std::string::npos) << result.err;
  const auto no_config = run_command({DYNID_CLI_EXE, "vehicles"}, 10s);
  EXPECT_EQ(no_config.exit_code, 2);
  EXPECT_NE(no_config.err.find("--cyclone-config"), std::string::npos) << no_config.err;
}

}  // namespace
}  // namespace dynid::e2e
