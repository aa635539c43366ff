#pragma once
// Shared by the end-to-end tests: a temporary folder, the loopback configuration with this
// process's discovery tag, the server in-process or as a child process, a test car publishing
// over DDS with the project's conversions, an estimate watcher, and the offline reference
// (ingest::RunProcessor on the same chunks). Every wait has a deadline.
#include <gtest/gtest.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "dynid.h"
#include "dynid/cli/request_client.hpp"
#include "dynid/dds/chunk_receipt.hpp"
#include "dynid/dds/estimate_table.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/dds/sample.hpp"
#include "dynid/dds/writer.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "dynid/server/server.hpp"
#include "ingest_test_support.hpp"
#include "temp_dir.hpp"

namespace dynid::e2e {

using namespace std::chrono_literals;

inline constexpr dds_domainid_t kDomain = 23;
inline constexpr std::chrono::milliseconds kPatience = 15s;  // discovery and folding under load

using ::dynid::test::TempDir;

/// deploy/cyclonedds/loopback.xml plus this process's discovery tag (without the tag after
/// use_open_network()).
std::string loopback_config();
/// The domain of this process's participants, the server's and the CLI's: kDomain unless
/// use_open_network() chose another.
dds_domainid_t domain();
/// loopback_config() plus deploy/cyclonedds/server-lease.xml, for servers of a scale-out: after a
/// SIGKILL, the cars' chunk writers wait for the dead server's reader until its DDS lease (2 s
/// there) expires.
std::string server_config();
/// tests/interop: everything on `domain_id` with loopback.xml and no discovery tag, since a
/// participant of another DDS implementation carries no Cyclone tag and a tagged participant
/// ignores it. The domain id of its own then isolates the test. Call before participant().
void use_open_network(dds_domainid_t domain_id);
dds::Participant& participant();  // one per test process, on domain()

server::ServerOptions server_options(const std::string& store_path);

/// The server in this process: run() on a thread, stopped and joined on destruction.
class InProcessServer {
 public:
  explicit InProcessServer(server::ServerOptions options);
  ~InProcessServer();
  server::Server& server() { return server_; }

 private:
  server::Server server_;
  std::thread thread_;
};

/// dynid-server as a child process (its output to `log`).
class ServerProcess {
 public:
  ServerProcess(const std::vector<std::string>& arguments, const std::string& log);
  ~ServerProcess();  // SIGKILL if still running
  void signal(int signal);
  /// Waits for the exit; its status (as waitpid) or nullopt on timeout.
  std::optional<int> wait(std::chrono::milliseconds timeout);

 private:
  pid_t pid_ = -1;
};

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};
/// Runs a program (no shell) and captures its output; exit_code -1 on timeout (then killed).
CommandResult run_command(const std::vector<std::string>& argv, std::chrono::milliseconds timeout);
/// The dynid CLI (DYNID_CLI_EXE) with the loopback configuration on `domain_id`, its request
/// timeout `timeout_s`; killed after twice that.
CommandResult run_dynid(const std::vector<std::string>& arguments, int timeout_s = 10,
                        std::optional<dds_domainid_t> domain_id = std::nullopt);  // domain()

/// A car: announces runs and publishes chunks of one vehicle, reads its acknowledgements.
class TestCar {
 public:
  explicit TestCar(const std::string& vehicle);
  void announce(const ingest::RunAnnouncement& announcement);
  void send(const ingest::Chunk& chunk);
  void send_raw(const dynid_wire_Chunk& sample);
  /// The latest receipt of `run` that satisfies `done`, or the last one seen at the deadline.
  std::optional<dds::ChunkReceipt> wait_receipt(const std::string& run,
                                                const std::function<bool(const dds::ChunkReceipt&)>& done,
                                                std::chrono::milliseconds patience = kPatience);
  /// The receipts that arrived since the last call, in arrival order, without waiting.
  std::vector<dds::ChunkReceipt> take_receipts();
  /// Waits until every sequence up to `last` is acknowledged.
  bool wait_acked(const std::string& run, std::int64_t last,
                  std::chrono::milliseconds patience = kPatience);
  /// As the car's spool does: sends chunks[from, end), and resends those after the highest
  /// acknowledged one while not all are acknowledged (a server that restarted or is not yet
  /// discovered has not received them; a chunk that overtook its run's announcement on the
  /// other topic was refused as of an unknown run). True once chunks up to end - 1 are
  /// acknowledged within kPatience.
  bool deliver(const std::vector<ingest::Chunk>& chunks, std::size_t from = 0,
               std::size_t end = std::size_t(-1));
  /// announce() then deliver().
  bool stream(const ingest::RunAnnouncement& announcement, const std::vector<ingest::Chunk>& chunks);

 private:
  std::string vehicle_;
  dds::Writer<dynid_wire_RunAnnouncement> announcements_;
  dds::Writer<dynid_wire_Chunk> chunks_;
  dds::Reader<dynid_wire_ChunkAck> acks_;
  std::map<std::string, dds::ChunkReceipt> latest_;
  std::vector<dds::ChunkReceipt> seen_;  // every receipt, in arrival order
};

struct Reference;

/// Estimates of one vehicle as published, checked by the vehicle id, the latest table per source
/// and model: a run's throttled publication may arrive after a pool's, so a test waiting for one
/// source must not have it replaced by another.
class EstimateWatcher {
 public:
  explicit EstimateWatcher(const std::string& vehicle);
  /// Waits until every expected model is published from `source` with the expected row count.
  bool wait_for(const std::vector<Reference>& expected, const std::string& source,
                std::chrono::milliseconds patience = kPatience);
  /// The latest table per model from `source` (empty when none came).
  const std::map<std::string, dds::EstimateTable>& latest(const std::string& source) const;
  std::size_t foreign() const { return foreign_; }  ///< tables of another vehicle (crosstalk)
  /// What was seen, for a failure message: per source, each model's latest row count.
  std::string seen() const;

 private:
  void take(std::chrono::milliseconds timeout);

  std::string vehicle_;
  dds::Reader<dynid_wire_Estimate> reader_;
  std::map<std::string, std::map<std::string, dds::EstimateTable>> by_source_;
  std::size_t foreign_ = 0;
};

/// The run cut into sealed chunks of random sizes (seeded), for `vehicle`/`run`.
std::vector<ingest::Chunk> cut_run(const ingest::test::TestRun& run, unsigned seed,
                                   Eigen::Index largest = 700);
ingest::test::TestRun test_run(const std::string& vehicle, const std::string& run, unsigned seed,
                               const ingest::test::Truth& truth = {});
/// The offline reference: one RunProcessor fed the same chunks.
ingest::RunProcessor offline(const ingest::test::TestRun& run, const std::vector<ingest::Chunk>& chunks);

/// Tables of the offline estimates (the server's own conversion is not used: names, values,
/// standard deviations and row counts come straight from ls::WeightedEstimate).
struct Reference {
  std::string model;
  std::vector<std::string> names;
  std::uint64_t rows = 0;
  Eigen::VectorXd value, std;
  double sigma = 0.0;
};
std::vector<Reference> references(const std::vector<ingest::ModelEstimate>& estimates);
Reference reference_of(const std::string& model, const std::vector<model::ParameterInfo>& parameters,
                       const ls::WeightedEstimate& estimate);

/// Values, standard deviations and sigma agree to `relative` (NaN matches NaN).
void expect_equal(const Reference& expected, const dds::EstimateTable& published,
                  double relative = 1e-12);

dds::Reply request(const std::string& kind, const std::vector<dds::RequestArgument>& arguments,
                   std::chrono::milliseconds patience = kPatience);

}  // namespace dynid::e2e
