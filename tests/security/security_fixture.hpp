#pragma once
// Shared by the DDS Security tests: a fresh PKI from deploy/security/make-pki.sh in a temporary
// folder, dynid-server as a child process on a secure (or, for the controls, plain loopback)
// configuration with a temporary SQLite store, security_peer processes (one identity each:
// Cyclone's access control holds one permissions document per process), and the store read
// back after the server stopped. Every configuration is the subject's generated file (loopback,
// deploy/cyclonedds/loopback.xml, plus its Security section) with this test process's discovery
// tag appended, so concurrent tests never see each other. Every wait is bounded.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <dds/dds.h>
#include "temp_dir.hpp"

namespace dynid::security_test {

using namespace std::chrono_literals;

inline constexpr dds_domainid_t kDomain = 29;

using ::dynid::test::TempDir;

/// What a finished program printed (stdout and stderr, interleaved) and its exit code
/// (-1: killed at the deadline, or ended by a signal).
struct Outcome {
  int exit_code = -1;
  std::string output;
};

/// Runs argv (argv[0] a path, no shell) to its end or the deadline (then SIGKILL).
Outcome run(const std::vector<std::string>& argv, std::chrono::milliseconds timeout);

/// The whole content of a file ("" if it cannot be read).
std::string read_text(const std::filesystem::path& file);

/// deploy/cyclonedds/loopback.xml (no security) plus this process's discovery tag.
std::string plain_config();

/// A PKI made by make-pki.sh in `dir`: config("car-A") is that subject's configuration.
class Pki {
 public:
  /// Runs make-pki.sh --out dir --days 1 with `subjects` (e.g. {"--car", "A"}); throws with the
  /// tool's output if it fails.
  Pki(const std::filesystem::path& dir, const std::vector<std::string>& subjects);
  std::string config(const std::string& subject) const;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

/// dynid-server on `config` with a store in `store`; its output goes to `log`.
class ServerProcess {
 public:
  ServerProcess(const std::string& config, const std::filesystem::path& store,
                const std::filesystem::path& log);
  ~ServerProcess();  // SIGKILL if still running
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;
  /// SIGTERM, then waits: the wait status, or -1 if it did not end in time (then killed).
  int stop();

 private:
  pid_t pid_ = -1;
};

/// security_peer on `config`, bounded by `seconds` (see security_peer.cpp for the actions and
/// exit codes: 0 done, 2 nothing came, 3 refused).
Outcome peer(const std::string& config, double seconds, const std::vector<std::string>& action);

/// The dynid CLI on `config` (e.g. {"vehicles"}).
Outcome cli(const std::string& config, const std::vector<std::string>& arguments);

/// vehicle -> run -> chunks stored, read from a stopped server's store.
using StoreContents = std::map<std::string, std::map<std::string, std::uint64_t>>;
StoreContents read_store(const std::filesystem::path& store);

/// Chunks in security_peer's synthetic run (6000 rows in chunks of 500).
inline constexpr std::uint64_t kRunChunks = 12;

}  // namespace dynid::security_test
