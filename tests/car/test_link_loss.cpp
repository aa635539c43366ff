// Link loss, end to end (labels e2e, slow): dynid-car replays a simulated run while dynid-server
// is stopped for 20 s and started again on the same store. Every chunk is stored exactly once
// and bit for bit (the server's store says so), and the final estimates equal those of the same
// log sent without interruption. Real processes, real Cyclone on loopback, real SQLite.
#include <gtest/gtest.h>

#include <csignal>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <dynid/store/store.hpp>

#include "client_fixture.hpp"

namespace dynid::car {
namespace {

using namespace testing;

const std::string kVehicle = "dynid-testcar";

struct Server {
  Server(const std::filesystem::path& store, const std::filesystem::path& log)
      : child({DYNID_SERVER, "--store", store.string(), "--cyclone-config", loopback_options().config, "--domain",
               std::to_string(kDomain)},
              log) {}
  /// SIGTERM, and the exit status (bounded).
  std::optional<int> stop() {
    child.signal(SIGTERM);
    return child.wait(15s);
  }
  Child child;
};

std::string cli(const ScratchDir& scratch, const std::vector<std::string>& args) {
  std::vector<std::string> argv{DYNID_CLI, "--cyclone-config", loopback_options().config, "--domain",
                                std::to_string(kDomain), "--timeout", "15"};
  argv.insert(argv.end(), args.begin(), args.end());
  const auto out = scratch.path() / "cli.out";
  std::filesystem::remove(out);
  Child c(argv, out);
  const auto status = c.wait(30s);
  EXPECT_EQ(status, 0) << read_text(out);
  return read_text(out);
}

// Every number of an estimate's JSON tables, in order ("source" and "revision" differ between
// the runs by design and are left out).
std::vector<double> numbers(std::string json, const std::string& run) {
  json = std::regex_replace(json, std::regex("\"source\":\"" + run + "\""), "");
  json = std::regex_replace(json, std::regex(R"("revision":\d+)"), "");
  std::vector<double> out;
  const std::regex number(R"(:(-?[0-9][0-9.eE+-]*|NaN|null))");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), number); it != std::sregex_iterator(); ++it)
    out.push_back((*it)[1] == "null" || (*it)[1] == "NaN" ? std::nan("") : std::stod((*it)[1]));
  return out;
}

TEST(ClientLinkLoss, ServerDownTwentySecondsMidRunLosesAndDuplicatesNothing) {
  ScratchDir scratch("link-loss");
  const auto run_dir = simulated_run("sine_steer", scratch);
  const auto log = run_dir / "can.log";
  const auto expected = expected_chunks(log, "lost-1");
  ASSERT_GE(expected.size(), 30U);
  const auto store = scratch.path() / "store.db";
  // OpenBLAS starts a thread when it loads, before dynid-server blocks SIGTERM for its sigwait
  // thread; with one BLAS thread the server's clean stop on SIGTERM works (see deploy/demo.sh).
  setenv("OPENBLAS_NUM_THREADS", "1", 1);

  auto server = std::make_unique<Server>(store, scratch.path() / "server-1.log");
  // Twice real time: 40 s of log in ~20 s, so the server is gone for part of the replay and
  // the rest waits in the spool.
  Child car({DYNID_CAR, "--profile", testcar_profile().string(), "--cyclone-config", loopback_options().config,
             "--domain", std::to_string(kDomain), "--spool", (scratch.path() / "spool").string(), "--run", "lost-1",
             "--replay", log.string(), "--speed", "2", "--ack-timeout", "2", "--drain-timeout", "60"},
            scratch.path() / "car.log");
  std::this_thread::sleep_for(5s);
  ASSERT_TRUE(car.running()) << read_text(scratch.path() / "car.log");
  ASSERT_EQ(server->stop(), 0) << read_text(scratch.path() / "server-1.log");
  server.reset();
  std::this_thread::sleep_for(20s);
  server = std::make_unique<Server>(store, scratch.path() / "server-2.log");
  const auto car_status = car.wait(90s);
  const std::string car_log = read_text(scratch.path() / "car.log");
  ASSERT_EQ(car_status, 0) << car_log;
  EXPECT_NE(car_log.find("resending"), std::string::npos) << "the car must have resent: " << car_log;

  // The same log, uninterrupted, as another run of the vehicle.
  Child reference({DYNID_CAR, "--profile", testcar_profile().string(), "--cyclone-config",
                   loopback_options().config, "--domain", std::to_string(kDomain), "--spool",
                   (scratch.path() / "spool-ref").string(), "--run", "ref-1", "--replay", log.string(), "--fast",
                   "--drain-timeout", "60"},
                  scratch.path() / "reference.log");
  ASSERT_EQ(reference.wait(90s), 0) << read_text(scratch.path() / "reference.log");

  cli(scratch, {"close", "--vehicle", kVehicle, "--run", "lost-1"});
  cli(scratch, {"close", "--vehicle", kVehicle, "--run", "ref-1"});
  const auto lost = numbers(cli(scratch, {"--json", "estimates", "--vehicle", kVehicle, "--run", "lost-1"}), "lost-1");
  const auto ref = numbers(cli(scratch, {"--json", "estimates", "--vehicle", kVehicle, "--run", "ref-1"}), "ref-1");
  ASSERT_GT(ref.size(), 50U);
  ASSERT_EQ(lost.size(), ref.size());
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (std::isnan(ref[i])) {
      EXPECT_TRUE(std::isnan(lost[i])) << i;
      continue;
    }
    EXPECT_NEAR(lost[i], ref[i], 1e-9 * std::max(1.0, std::abs(ref[i]))) << "number " << i;
  }
  ASSERT_EQ(server->stop(), 0) << read_text(scratch.path() / "server-2.log");

  // The server's ledger and archive: every chunk once, contiguous, bit for bit.
  store::Store s(store.string());
  std::optional<store::RunInfo> info;
  for (const auto& r : s.list_runs(kVehicle))
    if (r.run == "lost-1") info = r;
  ASSERT_TRUE(info.has_value());
  EXPECT_EQ(info->chunks_stored, expected.size());
  ASSERT_EQ(info->contiguous_through, expected.size() - 1);
  auto stream = s.chunks({kVehicle, "lost-1"}, 0, expected.size() - 1);
  std::size_t n = 0;
  while (auto c = stream.next()) {
    ASSERT_LT(n, expected.size());
    EXPECT_TRUE(same_chunk(*c, expected[n])) << "chunk " << n;
    ++n;
  }
  EXPECT_EQ(n, expected.size());
}

}  // namespace
}  // namespace dynid::car
