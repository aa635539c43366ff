// A request nobody waits for is not computed (dynid/cancellation.hpp): the trace of a client
// that exits is cancelled within seconds and its worker serves the vehicle again, and SIGTERM
// stops a server in the middle of a trace within seconds. Both are about time, so each first
// checks that the trace was still being computed when its client or the server went.
#include <signal.h>
#include <sys/wait.h>

#include <fstream>
#include <iterator>
#include <thread>

#include "child_process.hpp"
#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

using Clock = std::chrono::steady_clock;

// The CLI asking for a trace, as a child that the test can signal (output to `log`).
pid_t start_trace(const std::string& vehicle, const std::string& run, const std::string& log) {
  return test::spawn_child(
      {DYNID_CLI_EXE, "--cyclone-config", loopback_config(), "--domain", std::to_string(domain()),
       "--timeout", "600", "trace", "--vehicle", vehicle, "--run", run, "--model",
       "longitudinal_wheel", "--rounds", "10"},
      {.file = log});
}

// A 10-minute run (100 Hz): its trace takes far longer than the tests wait, on any machine.
ingest::test::TestRun long_run(const std::string& vehicle, const std::string& run, unsigned seed) {
  auto r = ingest::test::make_run(60000, seed);
  r.announcement.vehicle = vehicle;
  r.announcement.run = run;
  r.announcement.preprocessing = {};  // as test_run: the wire carries none
  return r;
}

std::optional<int> wait_exit(pid_t pid, std::chrono::milliseconds patience) {
  const auto deadline = Clock::now() + patience;
  while (Clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return std::nullopt;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(E2eCancellation, ATraceWhoseClientLeavesIsCancelledAndTheWorkerServesAgain) {
  TempDir dir;
  auto options = server_options(dir.file("store.db"));
  options.threads = 1;  // the trace holds the only worker: nothing else is answered until it ends
  InProcessServer server(options);
  const auto run = long_run("cancel-car", "run-c", 46u);
  TestCar car("cancel-car");
  ASSERT_TRUE(car.stream(run.announcement, cut_run(run, 9u)));

  const std::uint64_t before = server.server().counters().requests;
  const pid_t cli = start_trace("cancel-car", "run-c", dir.file("trace.log"));
  const auto received_by = Clock::now() + std::chrono::seconds(30);
  while (server.server().counters().requests == before && Clock::now() < received_by)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_GT(server.server().counters().requests, before) << "the trace request never arrived";
  std::this_thread::sleep_for(std::chrono::seconds(1));  // the worker is inside the trace

  kill(cli, SIGTERM);  // as Ctrl-C: the CLI leaves through its destructors
  const auto cli_status = wait_exit(cli, std::chrono::seconds(5));
  ASSERT_TRUE(cli_status.has_value()) << "the CLI did not exit on SIGTERM";
  EXPECT_TRUE(WIFEXITED(*cli_status) && WEXITSTATUS(*cli_status) == 130)
      << read_file(dir.file("trace.log"));
  EXPECT_NE(read_file(dir.file("trace.log")).find("interrupted by signal"), std::string::npos);

  const auto left = Clock::now();
  while (server.server().counters().requests_cancelled == 0 &&
         Clock::now() - left < std::chrono::seconds(5))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(server.server().counters().requests_cancelled, 1U)
      << "the trace was not cancelled within 5 s of its client leaving (or it had ended before)";
  // The worker is free: the vehicle's estimates answer at once.
  const auto estimates = run_dynid({"estimates", "--vehicle", "cancel-car", "--run", "run-c"}, 10);
  EXPECT_EQ(estimates.exit_code, 0) << estimates.err;
  EXPECT_LT(Clock::now() - left, std::chrono::seconds(8));
}

TEST(E2eCancellation, SigtermDuringATraceStopsTheServerWithinSeconds) {
  TempDir dir;
  ServerProcess server(
      {"--store", dir.file("store.db"), "--cyclone-config", loopback_config(), "--domain",
       std::to_string(domain()), "--threads", "1", "--log-level", "info"},
      dir.file("server.log"));
  const auto run = long_run("stop-car", "run-s", 47u);
  TestCar car("stop-car");
  ASSERT_TRUE(car.stream(run.announcement, cut_run(run, 9u))) << read_file(dir.file("server.log"));

  const pid_t cli = start_trace("stop-car", "run-s", dir.file("trace.log"));
  const auto received_by = Clock::now() + std::chrono::seconds(30);
  while (read_file(dir.file("server.log")).find("trace started") == std::string::npos &&
         Clock::now() < received_by)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_NE(read_file(dir.file("server.log")).find("trace started"), std::string::npos)
      << read_file(dir.file("server.log"));
  std::this_thread::sleep_for(std::chrono::seconds(1));  // inside the trace

  const auto signalled = Clock::now();
  server.signal(SIGTERM);
  const auto status = server.wait(std::chrono::seconds(5));
  const std::string log = read_file(dir.file("server.log"));
  ASSERT_TRUE(status.has_value()) << "the server did not stop within 5 s of SIGTERM\n" << log;
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << log;
  EXPECT_LT(Clock::now() - signalled, std::chrono::seconds(5));
  EXPECT_NE(log.find("cancelled: the server is stopping"), std::string::npos) << log;
  EXPECT_EQ(log.find("trace finished"), std::string::npos) << "the trace ended before the signal:\n"
                                                           << log;
  kill(cli, SIGKILL);
  wait_exit(cli, std::chrono::seconds(5));
}

}  // namespace
}  // namespace dynid::e2e
