// (e) The residual loop from the command line against a running server (docs/RESIDUAL.md):
// `dynid residual` ranks the candidate effects of a stored run's model, `dynid add-effect`
// reports before and after, `--html` writes the self-contained page; bad requests are named.
#include <fstream>
#include <sstream>

#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

CommandResult dynid(const std::vector<std::string>& arguments) { return run_dynid(arguments, 30); }

TEST(E2eResidualCli, RanksEffectsAndWritesTheBeforeAfterReport) {
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  const auto run = test_run("res-car", "run-r", 43u);
  TestCar car("res-car");
  ASSERT_TRUE(car.stream(run.announcement, cut_run(run, 9u)));

  const std::vector<std::string> where{"--vehicle", "res-car", "--run", "run-r", "--model", "kinematic_longitudinal"};
  std::vector<std::string> args{"residual"};
  args.insert(args.end(), where.begin(), where.end());
  const auto screen = dynid(args);
  ASSERT_EQ(screen.exit_code, 0) << screen.err;
  for (const std::string word : {"model kinematic_longitudinal", "candidate", "held-out%", "dict:sq:vx", "verdict:"})
    EXPECT_NE(screen.out.find(word), std::string::npos) << "missing '" << word << "' in\n" << screen.out;

  args = {"add-effect"};
  args.insert(args.end(), where.begin(), where.end());
  args.insert(args.end(), {"--effect", "dict:sq:vx"});
  const auto text = dynid(args);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  for (const std::string word : {"add dict:sq:vx to kinematic_longitudinal", "sensor_scale", "held out", "weighted residual RMS"})
    EXPECT_NE(text.out.find(word), std::string::npos) << "missing '" << word << "' in\n" << text.out;

  const std::string page = dir.file("report.html");
  args.insert(args.end(), {"--html", page});
  const auto html = dynid(args);
  ASSERT_EQ(html.exit_code, 0) << html.err;
  std::stringstream content;
  content << std::ifstream(page).rdbuf();
  EXPECT_EQ(content.str().rfind("<!DOCTYPE html>", 0), 0U);
  EXPECT_NE(content.str().find("data:image/png;base64,"), std::string::npos);

  const auto no_model = dynid({"residual", "--vehicle", "res-car", "--run", "run-r", "--model", "suspension_fl"});
  EXPECT_EQ(no_model.exit_code, 2);
  EXPECT_NE(no_model.err.find("has no model 'suspension_fl'"), std::string::npos) << no_model.err;
  args = {"add-effect"};
  args.insert(args.end(), where.begin(), where.end());
  args.insert(args.end(), {"--effect", "warp_drive"});
  const auto bad_effect = dynid(args);
  EXPECT_EQ(bad_effect.exit_code, 2);
  EXPECT_NE(bad_effect.err.find("warp_drive"), std::string::npos) << bad_effect.err;
  const auto json = request("residual", {{"vehicle", "res-car"}, {"run", "run-r"}, {"model", "kinematic_longitudinal"},
                                         {"format", "json"}});
  EXPECT_EQ(json.status, dds::ReplyStatus::kBadRequest);
  EXPECT_NE(json.error.find("neither text nor html"), std::string::npos) << json.error;
}

}  // namespace
}  // namespace dynid::e2e
