// DDS Security end to end (label security): a fresh PKI per test (deploy/security/make-pki.sh),
// dynid-server as a process on its secure configuration with a temporary SQLite store, and
// every other identity a security_peer process (or the dynid CLI) on loopback.
//
// Each negative test has its positive control in the same deployment (a legitimate car's run is
// acknowledged and stored), so a refusal cannot come from a server that is simply not there;
// and the control test runs the same intruding actions against a server without security,
// where they succeed within the same patience, so the negative tests would fail if security
// were off. What the server received is read from its store after it stopped.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <functional>
#include <future>
#include <optional>

#include "security_fixture.hpp"

namespace dynid::security_test {
namespace {

// How long a peer that must get nothing waits for something. Against a server without
// security the same actions succeed well within it (ControlWithoutSecurity...).
constexpr double kNegativePatience = 8.0;
constexpr double kPositivePatience = 40.0;

const std::string kAllAcked = "acked " + std::to_string(kRunChunks) + " of " + std::to_string(kRunChunks);
const std::string kRefusedBySecurity = "Not Allowed By Security";

class Security : public ::testing::Test {
 protected:
  TempDir dir;
  Pki pki{dir.path() / "pki", {"--server", "main", "--car", "A", "--car", "B", "--engineer", "alice"}};
  std::filesystem::path store = dir.path() / "store.db";
  std::filesystem::path log = dir.path() / "server.log";
  std::optional<ServerProcess> server;

  void start(const std::string& config) { server.emplace(config, store, log); }
  void start_secure() { start(pki.config("server-main")); }

  /// Stops the server (it must end cleanly) and returns what its store holds.
  StoreContents stop() {
    const int status = server->stop();
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "server status " << status << "\n" << server_log();
    return read_store(store);
  }
  std::string server_log() const { return read_text(log); }

  /// A legitimate car streams a run: acknowledged in full (the positive control).
  void stream(const std::string& car, const std::string& vehicle, const std::string& run) {
    const auto streamed = peer(pki.config(car), kPositivePatience, {"car", vehicle, run});
    ASSERT_EQ(streamed.exit_code, 0) << streamed.output << server_log();
    ASSERT_NE(streamed.output.find(kAllAcked), std::string::npos) << streamed.output;
  }
};

void expect_nothing(const Outcome& outcome, const std::string& what) {
  EXPECT_EQ(outcome.exit_code, 2) << what << ": " << outcome.output;
}

void expect_refused(const Outcome& outcome, const std::string& what) {
  EXPECT_EQ(outcome.exit_code, 3) << what << ": " << outcome.output;
  EXPECT_NE(outcome.output.find(kRefusedBySecurity), std::string::npos) << what << ": " << outcome.output;
}

// Runs peers at once (each waits out its patience; in a row they would add up).
std::vector<Outcome> together(const std::vector<std::function<Outcome()>>& calls) {
  std::vector<std::future<Outcome>> futures;
  for (const auto& call : calls) futures.push_back(std::async(std::launch::async, call));
  std::vector<Outcome> outcomes;
  for (auto& f : futures) outcomes.push_back(f.get());
  return outcomes;
}

// (1) The positive control: car A's identity streams, the engineer reads the estimates over
// DDS and through the dynid CLI.
TEST_F(Security, CarWithItsIdentityStreamsAndTheEngineerReadsItsEstimates) {
  start_secure();
  ASSERT_NO_FATAL_FAILURE(stream("car-A", "A", "run-1"));
  const auto estimates = peer(pki.config("engineer-alice"), kPositivePatience, {"estimates", "A"});
  EXPECT_EQ(estimates.exit_code, 0) << estimates.output;
  const auto vehicles = cli(pki.config("engineer-alice"), {"vehicles"});
  EXPECT_EQ(vehicles.exit_code, 0) << vehicles.output;
  EXPECT_NE(vehicles.output.find("A\n"), std::string::npos) << vehicles.output;
  const auto table = cli(pki.config("engineer-alice"), {"estimates", "--vehicle", "A"});
  EXPECT_EQ(table.exit_code, 0) << table.output;
  EXPECT_NE(table.output.find("A / longitudinal_wheel"), std::string::npos) << table.output;
  EXPECT_EQ(stop(), (StoreContents{{"A", {{"run-1", kRunChunks}}}}));
}

// (2) No security configuration, or an identity (and permissions) from another CA: nothing is
// read, nothing reaches the store.
TEST_F(Security, ParticipantsWithoutAValidIdentityNeitherReadEstimatesNorInjectChunks) {
  const Pki rogue(dir.path() / "rogue", {"--car", "A", "--engineer", "alice"});  // same names
  start_secure();
  ASSERT_NO_FATAL_FAILURE(stream("car-A", "A", "run-1"));
  const auto outcomes = together({
      [] { return peer(plain_config(), kNegativePatience, {"estimates", "A"}); },
      [] { return peer(plain_config(), kNegativePatience, {"car", "A", "run-plain"}); },
      [&] { return peer(rogue.config("engineer-alice"), kNegativePatience, {"estimates", "A"}); },
      [&] { return peer(rogue.config("car-A"), kNegativePatience, {"car", "A", "run-rogue"}); },
  });
  expect_nothing(outcomes[0], "no identity reads estimates");
  expect_nothing(outcomes[1], "no identity streams");
  expect_nothing(outcomes[2], "foreign CA reads estimates");
  expect_nothing(outcomes[3], "foreign CA streams");
  EXPECT_EQ(stop(), (StoreContents{{"A", {{"run-1", kRunChunks}}}}));
}

// (3) Car A may write only vehicle/A: its writer in vehicle/B is refused, and so is a reader of
// B's estimates; data keyed as B's but written in its own partition are dropped by the server
// (sender_partition.hpp); its own run works.
TEST_F(Security, CarCannotWriteOrReadAnotherCarsData) {
  start_secure();
  ASSERT_NO_FATAL_FAILURE(stream("car-B", "B", "run-b"));
  const auto outcomes = together({
      [&] { return peer(pki.config("car-A"), kNegativePatience, {"car", "B", "run-forged"}); },
      [&] { return peer(pki.config("car-A"), kNegativePatience, {"estimates", "B"}); },
      [&] { return peer(pki.config("car-A"), kNegativePatience, {"car", "A", "run-forged-key", "B"}); },
      [&] { return peer(pki.config("car-A"), kPositivePatience, {"car", "A", "run-a"}); },
  });
  expect_refused(outcomes[0], "car A writes vehicle/B");
  expect_refused(outcomes[1], "car A reads vehicle/B's estimates");
  expect_nothing(outcomes[2], "car A writes B's key in vehicle/A");
  EXPECT_EQ(outcomes[3].exit_code, 0) << "car A in its own partition: " << outcomes[3].output;
  EXPECT_EQ(stop(), (StoreContents{{"A", {{"run-a", kRunChunks}}}, {"B", {{"run-b", kRunChunks}}}}));
}

// (4) The engineer reads estimates and sends requests but cannot create a chunk writer; a car
// cannot send requests.
TEST_F(Security, EngineerReadsAndRequestsButCannotWriteChunks) {
  start_secure();
  ASSERT_NO_FATAL_FAILURE(stream("car-A", "A", "run-1"));
  const auto outcomes = together({
      [&] { return peer(pki.config("engineer-alice"), kNegativePatience, {"car", "A", "run-e"}); },
      [&] { return peer(pki.config("engineer-alice"), kPositivePatience, {"estimates", "A"}); },
      [&] { return peer(pki.config("engineer-alice"), kPositivePatience, {"request", "vehicles"}); },
      [&] { return peer(pki.config("car-A"), kNegativePatience, {"request", "vehicles"}); },
  });
  expect_refused(outcomes[0], "engineer writes chunks");
  EXPECT_EQ(outcomes[1].exit_code, 0) << "engineer reads estimates: " << outcomes[1].output;
  EXPECT_EQ(outcomes[2].exit_code, 0) << "engineer's request: " << outcomes[2].output;
  EXPECT_NE(outcomes[2].output.find("\nA\n"), std::string::npos) << outcomes[2].output;
  expect_refused(outcomes[3], "car sends a request");
  EXPECT_EQ(stop(), (StoreContents{{"A", {{"run-1", kRunChunks}}}}));
}

// The control: without security the very actions refused above succeed within the same
// patience (anyone streams as any vehicle, reads every estimate, sends requests), so each
// negative test above fails if the deployment runs without security.
TEST_F(Security, ControlWithoutSecurityTheSameActionsSucceed) {
  start(plain_config());
  const auto outcomes = together({
      [] { return peer(plain_config(), kNegativePatience, {"car", "A", "run-plain"}); },
      [] { return peer(plain_config(), kNegativePatience, {"car", "B", "run-forged"}); },
      [] { return peer(plain_config(), kNegativePatience, {"request", "vehicles"}); },
  });
  EXPECT_EQ(outcomes[0].exit_code, 0) << outcomes[0].output;
  EXPECT_EQ(outcomes[1].exit_code, 0) << outcomes[1].output;
  EXPECT_EQ(outcomes[2].exit_code, 0) << outcomes[2].output;
  const auto estimates = peer(plain_config(), kNegativePatience, {"estimates", "A"});
  EXPECT_EQ(estimates.exit_code, 0) << estimates.output;
  EXPECT_EQ(stop(), (StoreContents{{"A", {{"run-plain", kRunChunks}}}, {"B", {{"run-forged", kRunChunks}}}}));
}

}  // namespace
}  // namespace dynid::security_test
