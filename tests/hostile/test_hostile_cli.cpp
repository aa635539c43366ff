// dynid (the engineers' CLI) against hostile input (label hostile, client): numeric options at
// and past their limits, vehicle ids and run names outside the id rule, a configuration that is
// no regular file. All refused with exit 2 before anything is sent (no server runs here: a
// command that got through would wait for one and fail otherwise).
#include <gtest/gtest.h>

#include "hostile_support.hpp"

namespace dynid::hostile {
namespace {

std::vector<std::string> cli(std::vector<std::string> args) {
  args.insert(args.begin(), {"--cyclone-config", loopback_xml().string(), "--domain", "31"});
  return args;
}

// Case 3 of issue 19 for dynid.
TEST(HostileCli, NumericOptionsOutsideTheirLimitsAreRefused) {
  ScratchDir scratch("hostile-cli-numbers");
  const std::vector<NumericOption> options{
      {"--timeout", {"0", "0.0009", "86400.1", "-1"}, cli({}), {"vehicles"}},
      {"--domain", {"-1", "231"}, cli({}), {"vehicles"}},
      {"--seconds", {"0", "86400.1"}, cli({"watch", "--vehicle", "v1"})},
  };
  for (const auto& option : options) expect_refused(Program::Cli, option, 2, scratch);
}

// Case 6 of issue 19 for dynid: ids are checked before any request is sent.
TEST(HostileCli, IdsOutsideTheRuleAreRefusedBeforeAnyRequest) {
  ScratchDir scratch("hostile-cli-ids");
  for (const std::string& bad : std::vector<std::string>{"../../../escaped-vehicle", "a/b", ".x", "v*", "a\nb", std::string(65, 'v'), ""})
    for (const auto& command : std::vector<std::vector<std::string>>{
             {"runs", "--vehicle=" + bad},
             {"close", "--vehicle", "v1", "--run=" + bad},
             {"pooled", "--vehicle", "v1", "--run", "r1", "--run=" + bad},
             {"fleet", "m", "p", "--vehicles", "v1," + bad}}) {
      if (bad.empty() && command[0] != "fleet") continue;  // an empty option value is CLI11's
      SCOPED_TRACE(command[0] + " " + bad);
      auto args = cli({"--timeout", "0.3"});
      args.insert(args.end(), command.begin(), command.end());
      const Outcome o = run(Program::Cli, args, scratch, 10s);
      if (bad.empty()) {  // an empty item of a list is skipped, as the server skips it
        EXPECT_NE(o.exit, 2) << describe(o);
        continue;
      }
      EXPECT_EQ(o.exit, 2) << describe(o);
      EXPECT_LT(o.seconds, 1.5) << "refused before waiting for a server: " << describe(o);
      EXPECT_TRUE(o.output.find("vehicle id") != std::string::npos || o.output.find("run name") != std::string::npos)
          << describe(o);
    }
}

TEST(HostileCli, AConfigurationThatIsNoRegularFileIsRefused) {
  ScratchDir scratch("hostile-cli-files");
  const auto fifo = scratch.path() / "fifo";
  make_fifo(fifo);
  for (const auto& [bad, kind] : std::vector<std::pair<std::string, std::string>>{
           {fifo.string(), "FIFO"}, {scratch.path().string(), "directory"}, {"file://" + fifo.string(), "FIFO"}}) {
    SCOPED_TRACE(bad);
    const Outcome o = run(Program::Cli, {"--cyclone-config", bad, "--timeout", "1", "vehicles"}, scratch, 5s);
    EXPECT_EQ(o.exit, 2) << describe(o);
    EXPECT_NE(o.output.find(kind), std::string::npos) << describe(o);
  }
}

// An output that is no regular file (a FIFO would block the writer until something reads it):
// refused before any request, like an input.
TEST(HostileCli, AnHtmlReportThatIsNoRegularFileIsRefused) {
  ScratchDir scratch("hostile-cli-outputs");
  const auto fifo = scratch.path() / "fifo";
  make_fifo(fifo);
  for (const auto& command : std::vector<std::string>{"residual", "add-effect", "trace"})
    for (const auto& [bad, kind] : std::vector<std::pair<std::string, std::string>>{
             {fifo.string(), "FIFO"}, {scratch.path().string(), "directory"}}) {
      SCOPED_TRACE(command + " " + bad);
      auto args = cli({"--timeout", "1", command, "--vehicle", "v1", "--run", "r1", "--model", "m", "--html", bad});
      if (command == "add-effect") args.insert(args.end(), {"--effect", "road_grade"});
      const Outcome o = run(Program::Cli, args, scratch, 5s);
      EXPECT_EQ(o.exit, 2) << describe(o);
      EXPECT_NE(o.output.find(kind), std::string::npos) << describe(o);
      EXPECT_LT(o.seconds, 1.5) << "refused before waiting for a server: " << describe(o);
    }
}

}  // namespace
}  // namespace dynid::hostile
