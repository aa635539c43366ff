// dynid (the engineers' CLI) against hostile input (label hostile, client): numeric options at
// and past their limits, vehicle ids and run names outside the id rule, a configuration that is
// no regular file. All refused with exit 2 before anything is sent (no server runs here: a
// command that got through would wait for one and fail otherwise).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <future>
#include <iostream>
#include <memory>

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

// One environment variable gives the DDS configuration to all three programs (a remote engineer
// sets it once): a server, a CLI and a car started without --cyclone-config find each other.
TEST(HostileCli, OneEnvironmentVariableConfiguresAllThreePrograms) {
  ScratchDir scratch("hostile-cli-env");
  const std::string domain = std::to_string(150 + (getpid() + 40) % 80);
  const std::string config = "file://" + loopback_xml().string() + ",<Discovery><Tag>dynid-env-" +
                             std::to_string(getpid()) + "</Tag></Discovery>";
  ASSERT_EQ(setenv("DYNID_CYCLONE_CONFIG", config.c_str(), 1), 0);
  const Running server(Program::Server,
                       {"--store", (scratch.path() / "store.db").string(), "--domain", domain},
                       scratch.path() / "server.log");
  const Outcome listed = run(Program::Cli, {"--domain", domain, "vehicles"}, scratch, 30s);
  // The car delivers what its spool holds (nothing) and ends.
  const Outcome car = run(Program::Car,
                          {"--profile", testcar_profile().string(), "--spool",
                           (scratch.path() / "spool").string(), "--domain", domain},
                          scratch, 30s);
  unsetenv("DYNID_CYCLONE_CONFIG");
  EXPECT_EQ(listed.exit, 0) << describe(listed)
                            << "\nserver: " << read_text(scratch.path() / "server.log");
  EXPECT_NE(listed.output.find("no vehicles yet"), std::string::npos) << describe(listed);
  EXPECT_EQ(car.exit, 0) << describe(car);
  const Outcome without =
      run(Program::Server, {"--store", (scratch.path() / "b.db").string()}, scratch, 10s);
  EXPECT_NE(without.exit, 0);
  EXPECT_NE(without.output.find("--cyclone-config"), std::string::npos) << describe(without);
}

// A request storm: more CLIs at once than the Cyclone configuration has participant indices (one
// per process on a host and domain). They failed at once with Cyclone's bare "Error" (136 of 200
// against loopback.xml's 60); each now retries for up to 20 s and succeeds once others end,
// and one that cannot says why and what to raise. Here the configuration allows 4 processes: the
// server and 10 CLIs at once, then 3 watchers holding the rest. Its own domain (from the pid) and
// tag, on loopback without multicast: the indices of a domain are the whole host's.
TEST(HostileCli, ARequestStormWaitsForAParticipantIndexOrSaysWhatToRaise) {
  ScratchDir scratch("hostile-cli-storm");
  const std::string domain = std::to_string(150 + getpid() % 80);
  const std::string config =
      "file://" + loopback_xml().string() + ",<Discovery><Tag>dynid-storm-" +
      std::to_string(getpid()) +
      "</Tag><MaxAutoParticipantIndex>4</MaxAutoParticipantIndex></Discovery>";
  const std::vector<std::string> connection{"--cyclone-config", config, "--domain", domain};
  std::vector<std::string> server_args{"--store", (scratch.path() / "store.db").string()};
  server_args.insert(server_args.end(), connection.begin(), connection.end());
  const Running server(Program::Server, server_args, scratch.path() / "server.log");
  std::vector<std::string> request = connection;
  request.insert(request.end(), {"--timeout", "10", "vehicles"});
  const Outcome first = run(Program::Cli, request, scratch, 20s);  // the server holds its index
  ASSERT_EQ(first.exit, 0) << describe(first)
                           << "\nserver: " << read_text(scratch.path() / "server.log");

  const auto storm = [&](int clients) {
    std::vector<std::unique_ptr<ScratchDir>> dirs;
    std::vector<std::future<Outcome>> outcomes;
    for (int i = 0; i < clients; ++i) {
      dirs.push_back(std::make_unique<ScratchDir>("hostile-cli-storm-" + std::to_string(i)));
      outcomes.push_back(std::async(std::launch::async, [&, dir = dirs.back().get()] {
        return run(Program::Cli, request, *dir, 30s);
      }));
    }
    std::vector<Outcome> out;
    for (auto& o : outcomes) out.push_back(o.get());
    return out;
  };
  double slowest = 0.0;
  for (const Outcome& o : storm(10)) {
    EXPECT_EQ(o.exit, 0) << describe(o);
    slowest = std::max(slowest, o.seconds);
  }
  std::cout << "10 CLIs at once, 3 free participant indices: the slowest answered in " << slowest
            << " s\n";

  // Every index held (the server and three watchers): the CLI retries, then says what to do.
  std::vector<std::unique_ptr<Running>> watchers;
  for (int i = 0; i < 3; ++i) {
    std::vector<std::string> watch = connection;
    watch.insert(watch.end(), {"watch", "--vehicle", "v1", "--seconds", "60"});
    watchers.push_back(std::make_unique<Running>(Program::Cli, watch,
                                                 scratch.path() / ("watch" + std::to_string(i))));
  }
  std::this_thread::sleep_for(1500ms);  // each has joined the domain
  const Outcome refused = run(Program::Cli, request, scratch, 60s);
  EXPECT_EQ(refused.exit, 7) << describe(refused);
  EXPECT_GT(refused.seconds, 19.0) << "retried for 20 s first: " << describe(refused);
  for (const std::string& said :
       {"no free DDS participant index on this host for domain " + domain, std::string(" times)"),
        std::string("raise Discovery/MaxAutoParticipantIndex")})
    EXPECT_NE(refused.output.find(said), std::string::npos) << said << " in " << describe(refused);
  EXPECT_EQ(refused.output.find("Failed to find a free participant index"), std::string::npos)
      << "said once, in dynid's words: " << describe(refused);
  // A car and a second server say the same at start, without waiting.
  std::vector<std::string> car{"--profile", testcar_profile().string(), "--spool",
                               (scratch.path() / "spool").string()};
  std::vector<std::string> second_server{"--store", (scratch.path() / "second.db").string()};
  for (auto* args : {&car, &second_server})
    args->insert(args->end(), connection.begin(), connection.end());
  for (const auto& [program, args] :
       {std::make_pair(Program::Car, car), std::make_pair(Program::Server, second_server)}) {
    const Outcome o = run(program, args, scratch, 10s);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_LT(o.seconds, 2.0) << describe(o);
    EXPECT_NE(
        o.output.find("no free DDS participant index on this host for domain " + domain + ": "),
        std::string::npos)
        << describe(o);
  }

  // One ends while the CLI waits: it gets the index and its answer.
  auto late =
      std::async(std::launch::async, [&] { return run(Program::Cli, request, scratch, 30s); });
  std::this_thread::sleep_for(1s);
  watchers.pop_back();
  const Outcome answered = late.get();
  EXPECT_EQ(answered.exit, 0) << describe(answered);
}

}  // namespace
}  // namespace dynid::hostile
