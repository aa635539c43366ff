// (d) The dynid executable against a running server: `dynid estimates --vehicle V` prints the
// table (parameter, unit, value, std, relative std %, status; rows, sigma, cond, residual RMS),
// the other commands answer, and without a server it says so within its timeout.
#include <gtest/gtest-spi.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

CommandResult dynid(const std::vector<std::string>& arguments) { return run_dynid(arguments); }

// A server on a temporary store that has folded one streamed test run and published its
// estimates (`ready` false, and the test stops, when they did not come).
struct ServedRun {
  ServedRun(const std::string& vehicle, const std::string& run_id, unsigned seed)
      : server(server_options(dir.file("store.db"))), run(test_run(vehicle, run_id, seed)),
        chunks(cut_run(run, 8u)), watcher(vehicle) {
    TestCar car(vehicle);
    ready = car.stream(run.announcement, chunks) &&
            watcher.wait_for(references(offline(run, chunks).estimates()), run_id);
  }
  TempDir dir;
  InProcessServer server;
  ingest::test::TestRun run;
  std::vector<ingest::Chunk> chunks;
  EstimateWatcher watcher;
  bool ready = false;
};

TEST(E2eCli, EstimatesTableAgainstRunningServer) {
  ServedRun served("cli-car", "run-c", 41u);
  ASSERT_TRUE(served.ready);
  auto& watcher = served.watcher;

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

  // Issue 16 item 4: the excitation report of the same run says, per model, what the tables say.
  const auto excitation = dynid({"excitation", "--vehicle", "cli-car"});
  ASSERT_EQ(excitation.exit_code, 0) << excitation.err;
  EXPECT_NE(excitation.out.find("cli-car / run run-c: what this run identifies"), std::string::npos) << excitation.out;
  EXPECT_NE(excitation.out.find("  longitudinal_wheel: identifies "), std::string::npos) << excitation.out;
  const auto excitation_json = dynid({"--json", "excitation", "--vehicle", "cli-car", "--run", "run-c"});
  ASSERT_EQ(excitation_json.exit_code, 0) << excitation_json.err;
  const auto all = dynid({"--json", "estimates", "--vehicle", "cli-car", "--run", "run-c"});
  const auto report = nlohmann::json::parse(excitation_json.out);
  const auto tables = nlohmann::json::parse(all.out)["tables"];
  ASSERT_EQ(report["models"].size(), tables.size()) << excitation_json.out;
  for (std::size_t m = 0; m < tables.size(); ++m) {
    ASSERT_EQ(report["models"][m]["model"], tables[m]["model"]);
    ASSERT_EQ(report["models"][m]["parameters"].size(), tables[m]["parameters"].size());
    for (std::size_t j = 0; j < tables[m]["parameters"].size(); ++j)
      EXPECT_EQ(report["models"][m]["parameters"][j]["status"], tables[m]["parameters"][j]["status"]);
  }

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

// Issue 16, item 6: what an engineer follows live. `watch --model` shows that model only,
// compact (appended blocks on a pipe), JSON lines with --json; `status` and `runs` are text
// with columns that say what they count.
TEST(E2eCli, WatchOneModelAndTextForPeople) {
  ServedRun served("watch-car", "run-w", 43u);
  ASSERT_TRUE(served.ready);
  const auto& chunks = served.chunks;

  const auto watch = dynid({"watch", "--vehicle", "watch-car", "--model", "longitudinal_wheel", "--seconds", "1.5"});
  ASSERT_EQ(watch.exit_code, 0) << watch.err;
  EXPECT_EQ(watch.out.rfind("watch-car / longitudinal_wheel  source run-w, revision ", 0), 0u) << watch.out;
  for (const std::string word : {"parameter", "value", "std", "rel.std%", "status", "moved since last", "mass"})
    EXPECT_NE(watch.out.find(word), std::string::npos) << "missing '" << word << "' in\n" << watch.out;
  EXPECT_EQ(watch.out.find("locked_driveline"), std::string::npos) << watch.out;
  EXPECT_EQ(watch.out.find('\x1b'), std::string::npos) << "no cursor moves on a pipe";

  const auto lines = dynid({"--json", "watch", "--vehicle", "watch-car", "--model", "locked_driveline", "--seconds", "1.5"});
  ASSERT_EQ(lines.exit_code, 0) << lines.err;
  std::istringstream in(lines.out);
  std::size_t count = 0;
  for (std::string line; std::getline(in, line); ++count) {
    const auto sample = nlohmann::json::parse(line);
    EXPECT_EQ(sample["model"], "locked_driveline") << line;
    EXPECT_EQ(sample["source"], "run-w") << line;
    EXPECT_TRUE(sample["parameters"][0].contains("status")) << line;
  }
  EXPECT_GE(count, 1u) << lines.out;
  const auto nothing = dynid({"watch", "--vehicle", "watch-car", "--model", "no_such_model", "--seconds", "1"});
  EXPECT_EQ(nothing.exit_code, 5);
  EXPECT_NE(nothing.err.find("no estimate of watch-car model no_such_model"), std::string::npos) << nothing.err;

  const auto status = dynid({"status"});
  ASSERT_EQ(status.exit_code, 0) << status.err;
  EXPECT_EQ(status.out.find('{'), std::string::npos) << status.out;
  const std::string n = std::to_string(chunks.size());
  EXPECT_TRUE(std::regex_search(status.out, std::regex("chunks stored durably \\(acknowledged\\) +" + n + "\n")))
      << status.out;
  const auto raw = dynid({"--json", "status"});
  EXPECT_EQ(nlohmann::json::parse(raw.out)["chunks_stored"], chunks.size()) << raw.out;

  const auto runs = dynid({"runs", "--vehicle", "watch-car"});
  ASSERT_EQ(runs.exit_code, 0) << runs.err;
  EXPECT_TRUE(std::regex_search(runs.out, std::regex("run +state +stored +in order +folded +complete\n"))) << runs.out;
  EXPECT_TRUE(std::regex_search(runs.out, std::regex("run-w +open +" + n + " +" + n + " +" + n + " +so far \\(run open\\)\n"))) << runs.out;
  EXPECT_NE(runs.out.find("in order = stored without a gap from chunk #0"), std::string::npos) << runs.out;
  ASSERT_EQ(dynid({"close", "--vehicle", "watch-car", "--run", "run-w"}).exit_code, 0);
  const auto closed = dynid({"runs", "--vehicle", "watch-car"});
  EXPECT_TRUE(std::regex_search(closed.out, std::regex("run-w +closed +" + n + " +" + n + " +" + n + " +yes\n"))) << closed.out;
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

TEST(E2eCli, AnEmptyServerSaysItIsEmpty) {
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  const auto text = dynid({"vehicles"});
  EXPECT_EQ(text.exit_code, 0) << text.err;
  EXPECT_EQ(text.out, "no vehicles yet: a car's first run announces its vehicle\n") << text.err;
  const auto json = dynid({"--json", "vehicles"});
  EXPECT_EQ(json.out, "[]\n") << json.err;
}

// CLI11's help, one program or subcommand: every option, positional and subcommand has a
// description (on its line, or on the next when the name and type fill the column), and an option
// about a count or a duration is typed as a number. Returns the subcommands' names.
std::vector<std::string> expect_help_explains(const std::string& program, const std::string& help) {
  std::vector<std::string> subcommands;
  std::istringstream in(help);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::string section;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    if (!line.empty() && line.back() == ':' && line.front() != ' ') section = line;
    if (line.rfind("  ", 0) != 0 || line.rfind("   ", 0) == 0) continue;  // entries: 2 spaces in
    // CLI11 starts a description at column 30 (kColumn), or on the next line past it.
    constexpr std::size_t kColumn = 30;
    const bool described_here =
        line.size() > kColumn && line[kColumn - 1] == ' ' && line[kColumn] != ' ';
    const bool described_next = i + 1 < lines.size() &&
                                lines[i + 1].rfind(std::string(20, ' '), 0) == 0 &&
                                lines[i + 1].find_first_not_of(' ') != std::string::npos;
    EXPECT_TRUE(described_here || described_next)
        << program << ": no help text for `" << line << "`";
    const std::string description = described_here ? line : (described_next ? lines[i + 1] : "");
    if (section == "Options:" && std::regex_search(line, std::regex("^  --\\S+ TEXT\\b"))) {
      EXPECT_FALSE(std::regex_search(description, std::regex("\\b(seconds|how many|number of)\\b")))
          << program << ": `" << line << "` takes a number but is typed TEXT";
    }
    if (section == "Subcommands:") subcommands.push_back(line.substr(2, line.find(' ', 2) - 2));
  }
  return subcommands;
}

// The CLI explains itself: every subcommand's and option's help, the option types, and the one
// environment variable for the DDS configuration in all three programs.
TEST(E2eCli, EveryOptionAndSubcommandIsExplained) {
  // The check itself fails on an option without help and on a duration typed as text.
  EXPECT_NONFATAL_FAILURE(expect_help_explains("x", "Options:\n  --bare TEXT\n"), "no help text");
  EXPECT_NONFATAL_FAILURE(
      expect_help_explains("x", "Options:\n  --wait TEXT                 seconds to wait\n"),
      "typed TEXT");
  const auto top = run_command({DYNID_CLI_EXE, "--help"}, 10s);
  ASSERT_EQ(top.exit_code, 0) << top.err;
  const std::vector<std::string> subcommands = expect_help_explains("dynid", top.out);
  EXPECT_GE(subcommands.size(), 20u) << top.out;
  for (const std::string& sub : subcommands) {
    const auto help = run_command({DYNID_CLI_EXE, sub, "--help"}, 10s);
    ASSERT_EQ(help.exit_code, 0) << sub << ": " << help.err;
    expect_help_explains("dynid " + sub, help.out);
  }
  const auto trace = run_command({DYNID_CLI_EXE, "trace", "--help"}, 10s);
  EXPECT_TRUE(std::regex_search(trace.out, std::regex("--rounds INT"))) << trace.out;
  for (const std::string exe :
       {DYNID_CLI_EXE, DYNID_SERVER_EXE, DYNID_CAR_EXE, DYNID_DASHBOARD_EXE}) {
    const auto help = run_command({exe, "--help"}, 10s);
    ASSERT_EQ(help.exit_code, 0) << exe << ": " << help.err;
    if (exe != DYNID_CLI_EXE) expect_help_explains(exe, help.out);
    EXPECT_NE(help.out.find("DYNID_CYCLONE_CONFIG"), std::string::npos) << exe << "\n" << help.out;
  }
}

// The catalogue is answered without a server or a DDS configuration, from the models' own code:
// every model, what it reads (a constant its constructor asks for), its effects; an unknown name
// is answered with the known ones; docs/PROFILES.md's table is the one the program prints.
TEST(E2eCli, ModelsAndEffectsAreAnsweredWithoutAServer) {
  const auto models = run_command({DYNID_CLI_EXE, "models"}, 10s);
  ASSERT_EQ(models.exit_code, 0) << models.err;
  for (const char* name : {"longitudinal_engine", "lateral_bicycle", "clutch_slip", "tyre_rr"})
    EXPECT_NE(models.out.find(std::string(name) + "\n  channels:"), std::string::npos)
        << name << " in " << models.out;
  const auto engine = run_command({DYNID_CLI_EXE, "models", "--model", "longitudinal_engine"}, 10s);
  ASSERT_EQ(engine.exit_code, 0) << engine.err;
  EXPECT_TRUE(std::regex_search(engine.out, std::regex("\n  channels: +[^\n]*engine_torque")))
      << engine.out;
  EXPECT_TRUE(std::regex_search(
      engine.out, std::regex("\n  constants: +wheel_radius, air_density, driveline_efficiency\n")))
      << engine.out;
  EXPECT_TRUE(std::regex_search(engine.out,
                                std::regex("optional constants: [^\n]*min_speed \\(default 1\\)")))
      << engine.out;
  EXPECT_TRUE(std::regex_search(engine.out, std::regex("identifies: +mass, "))) << engine.out;
  const auto effects =
      run_command({DYNID_CLI_EXE, "effects", "--model", "longitudinal_wheel"}, 10s);
  ASSERT_EQ(effects.exit_code, 0) << effects.err;
  EXPECT_NE(effects.out.find("\n  road_grade: grade load"), std::string::npos) << effects.out;
  EXPECT_NE(effects.out.find("adds channels: road_grade\n"), std::string::npos) << effects.out;
  EXPECT_NE(effects.out.find("dict:<op>:<channel>"), std::string::npos) << effects.out;
  const auto unknown = run_command({DYNID_CLI_EXE, "effects", "--model", "longitudnal_wheel"}, 10s);
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("unknown model 'longitudnal_wheel' (known: body "), std::string::npos)
      << unknown.err;

  const auto table = run_command({DYNID_CLI_EXE, "models", "--markdown"}, 10s);
  ASSERT_EQ(table.exit_code, 0) << table.err;
  std::ifstream doc(std::string(DYNID_SOURCE_DIR) + "/docs/PROFILES.md");
  std::stringstream text;
  text << doc.rdbuf();
  EXPECT_NE(text.str().find(table.out), std::string::npos)
      << "docs/PROFILES.md holds the table `dynid models --markdown` prints:\n"
      << table.out;
}

}  // namespace
}  // namespace dynid::e2e
