#include "security_fixture.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "child_process.hpp"
#include "dynid/store/store.hpp"

namespace dynid::security_test {

namespace {

std::string process_tag() {
  static const std::string tag =
      "dynid-security-" + std::to_string(getpid()) + "-" +
      std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
  return tag;
}

std::string with_tag(const std::string& uri) {
  return uri + ",<Discovery><Tag>" + process_tag() + "</Tag></Discovery>";
}

// fork + exec with stdout and stderr into `log` (appended).
pid_t spawn(const std::vector<std::string>& argv, const std::filesystem::path& log) {
  return test::spawn_child(argv, {.file = log.string()});
}

// The wait status, or -1 if `pid` did not end by the deadline (then it is killed and reaped).
int reap(pid_t pid, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    std::this_thread::sleep_for(10ms);
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return -1;
}

}  // namespace

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

Outcome run(const std::vector<std::string>& argv, std::chrono::milliseconds timeout) {
  const TempDir scratch;  // one per call: calls may run on several threads at once
  const auto log = scratch.path() / "output";
  const int status = reap(spawn(argv, log), timeout);
  return {status >= 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(log)};
}

std::string plain_config() {
  return with_tag("file://" + std::string(DYNID_SOURCE_DIR) + "/deploy/cyclonedds/loopback.xml");
}

Pki::Pki(const std::filesystem::path& dir, const std::vector<std::string>& subjects) : dir_(dir) {
  std::vector<std::string> argv{std::string(DYNID_SOURCE_DIR) + "/deploy/security/make-pki.sh",
                                "--out", dir.string(), "--days", "1"};
  argv.insert(argv.end(), subjects.begin(), subjects.end());
  const auto made = run(argv, 60s);
  if (made.exit_code != 0) throw std::runtime_error("make-pki.sh failed: " + made.output);
}

std::string Pki::config(const std::string& subject) const {
  return with_tag("file://" + (dir_ / subject / "cyclonedds.xml").string());
}

ServerProcess::ServerProcess(const std::string& config, const std::filesystem::path& store,
                             const std::filesystem::path& log)
    : pid_(spawn({DYNID_SERVER_EXE, "--store", store.string(), "--cyclone-config", config,
                  "--domain", std::to_string(kDomain), "--threads", "2", "--publish-interval-ms",
                  "20", "--log-level", "warn"},
                 log)) {}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) reap(pid_, 0ms);
}

int ServerProcess::stop() {
  kill(pid_, SIGTERM);
  const int status = reap(pid_, 20s);
  pid_ = -1;
  return status;
}

Outcome peer(const std::string& config, double seconds, const std::vector<std::string>& action) {
  std::vector<std::string> argv{DYNID_SECURITY_PEER_EXE, config, std::to_string(kDomain),
                                std::to_string(seconds)};
  argv.insert(argv.end(), action.begin(), action.end());
  // The participant's creation (certificates, handshakes) and shutdown come on top of `seconds`.
  return run(argv, std::chrono::milliseconds(static_cast<long>(seconds * 1000)) + 30s);
}

Outcome cli(const std::string& config, const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{DYNID_CLI_EXE, "--cyclone-config", config, "--domain",
                                std::to_string(kDomain), "--timeout", "15"};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return run(argv, 45s);
}

StoreContents read_store(const std::filesystem::path& file) {
  store::Store store(file.string());
  StoreContents contents;
  for (const auto& vehicle : store.list_vehicles())
    for (const auto& run : store.list_runs(vehicle)) contents[vehicle][run.run] = run.chunks_stored;
  return contents;
}

}  // namespace dynid::security_test
