// Interop (issue 18): fastdds_peer, a Fast DDS 2.9 client built by fastddsgen from idl/dynid.idl,
// against the dynid-server executable, as a third party would use dynid (docs/INTEROP.md):
//   (a) it receives every model's estimate live and as a late joiner, tables equal to
//       `dynid estimates --json` (values, std, statuses, names, revisions, every field);
//   (b) its `estimate` request gets the reply `dynid` gets, for OK and for NOT_FOUND;
//   (c) acting as a car it announces a run and streams its chunks (checksums computed from the
//       documented encoding), which the server acknowledges and folds to the same estimate as
//       the same chunks from TestCar, which uses dynid's own conversions; a chunk it sends
//       with a wrong checksum is refused with the reason and changes nothing.
// Everything runs on loopback with multicast off, on a domain id of this test process's own and
// without a discovery tag (e2e::use_open_network): a Fast DDS participant has no Cyclone tag.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <span>
#include <sstream>

#include "child_process.hpp"
#include "dynid/dds/conversions.hpp"
#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

// 100..219: another domain than the tagged tests' (kDomain) and within the CLI's range; two
// interop tests running at once collide only if their pids agree modulo 120.
dds_domainid_t own_domain() {
  return static_cast<dds_domainid_t>(100 + getpid() % 120);
}

std::string fastdds_profile() {
  return std::string(DYNID_SOURCE_DIR) + "/deploy/fastdds/loopback.xml";
}

std::vector<std::string> peer_argv(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{FASTDDS_PEER_EXE, "--profile", fastdds_profile(), "--domain",
                                std::to_string(domain())};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return argv;
}

CommandResult peer(const std::vector<std::string>& arguments) {
  return run_command(peer_argv(arguments), std::chrono::seconds(60));
}

// fastdds_peer in the background, its stdout to `out`; SIGTERM (which it handles) on destruction.
class BackgroundPeer {
 public:
  BackgroundPeer(const std::vector<std::string>& arguments, const std::string& out) {
    pid_ = test::spawn_child(peer_argv(arguments), {.file = out, .append = false, .stderr_to_file = false});
  }
  ~BackgroundPeer() {
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
  }
  BackgroundPeer(const BackgroundPeer&) = delete;
  BackgroundPeer& operator=(const BackgroundPeer&) = delete;

 private:
  pid_t pid_ = -1;
};

std::vector<nlohmann::json> json_lines(const std::string& text) {
  std::vector<nlohmann::json> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(nlohmann::json::parse(line));
  return out;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// `dynid estimates --vehicle V --json`: its tables by model.
std::map<std::string, nlohmann::json> cli_tables(const std::string& vehicle) {
  const auto result = run_dynid({"--json", "estimates", "--vehicle", vehicle});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  std::map<std::string, nlohmann::json> out;
  if (result.exit_code != 0) return out;
  const auto reply = nlohmann::json::parse(result.out);
  for (const auto& table : reply.at("tables")) out[table.at("model").get<std::string>()] = table;
  EXPECT_FALSE(out.empty()) << "dynid estimates --vehicle " << vehicle << " --json: " << result.out;
  return out;
}

// A dynid-server process on this test's open network, with a store in `dir`.
struct Server {
  explicit Server(const TempDir& dir)
      : process({"--store", dir.file("store.db"), "--cyclone-config", loopback_config(), "--domain",
                 std::to_string(domain()), "--threads", "2", "--log-level", "warn"},
                dir.file("server.log")) {}
  ServerProcess process;
};

// The run file of `fastdds_peer car`: the announcement and the chunks as a third party would
// hold them (no vehicle: the peer's --vehicle; no checksum: the peer computes it). The
// announcement is read from dynid's own wire conversion, so both cars announce the same run.
nlohmann::json announcement_json(const ingest::RunAnnouncement& announcement) {
  const auto wire = dds::to_wire(announcement);
  const dynid_wire_RunAnnouncement& a = wire.data;
  nlohmann::json channels = nlohmann::json::array(), models = nlohmann::json::array();
  nlohmann::json noise = nlohmann::json::object();
  for (const auto& c : std::span(a.channels._buffer, a.channels._length))
    channels.push_back({{"name", c.name}, {"unit", c.unit}});
  for (const auto& m : std::span(a.models._buffer, a.models._length)) {
    nlohmann::json constants = nlohmann::json::object(), effects = nlohmann::json::array();
    for (const auto& c : std::span(m.constants._buffer, m.constants._length))
      constants[c.name] = c.value;
    for (const auto& e : std::span(m.effects._buffer, m.effects._length)) effects.push_back(e);
    models.push_back({{"model", m.model}, {"constants", constants}, {"effects", effects}});
  }
  for (const auto& n : std::span(a.channel_noise._buffer, a.channel_noise._length))
    noise[n.name] = n.value;
  return {{"run", a.run},
          {"sample_rate_hz", a.sample_rate_hz},
          {"channels", channels},
          {"models", models},
          {"butterworth_order", a.butterworth_order},
          {"cutoff_hz", a.cutoff_hz},
          {"odmf", a.odmf},
          {"channel_noise", noise}};
}

nlohmann::json chunk_json(const ingest::Chunk& c) {
  std::vector<double> data;  // row-major, as on the wire
  for (Eigen::Index i = 0; i < c.samples.rows(); ++i)
    for (Eigen::Index j = 0; j < c.samples.cols(); ++j) data.push_back(c.samples(i, j));
  return {{"sequence_number", c.sequence},
          {"first_sample_index", c.first_sample_index},
          {"rows", c.samples.rows()},
          {"channels", c.samples.cols()},
          {"data", data},
          {"valid", c.valid}};
}

nlohmann::json run_file(const ingest::RunAnnouncement& announcement,
                        const std::vector<ingest::Chunk>& chunks) {
  nlohmann::json out = {{"announcement", announcement_json(announcement)},
                        {"chunks", nlohmann::json::array()}};
  for (const auto& c : chunks) out["chunks"].push_back(chunk_json(c));
  return out;
}

class Interop : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { use_open_network(own_domain()); }

  // TestCar streams a test run of `vehicle`; true once the server published every model's
  // estimate of all of it.
  bool stream_with_test_car(const std::string& vehicle, const std::string& run_id) {
    run_ = test_run(vehicle, run_id, 3u);
    chunks_ = cut_run(run_, 8u);
    EstimateWatcher watcher(vehicle);
    TestCar car(vehicle);
    return car.stream(run_.announcement, chunks_) &&
           watcher.wait_for(references(offline(run_, chunks_).estimates()), run_id);
  }

  TempDir dir_;
  Server server_{dir_};
  ingest::test::TestRun run_;
  std::vector<ingest::Chunk> chunks_;
};

// (a) live and late-joining Fast DDS readers of dynid/Estimate.
TEST_F(Interop, FastDdsReaderGetsEveryEstimateLiveAndAsLateJoiner) {
  const std::string live_file = dir_.file("live.jsonl");
  {
    BackgroundPeer live({"estimates", "--vehicle", "interop-car", "--seconds", "120"}, live_file);
    std::this_thread::sleep_for(1s);  // discovered before the first table is published
    ASSERT_TRUE(stream_with_test_car("interop-car", "run-a"));
    const auto expected = cli_tables("interop-car");
    ASSERT_FALSE(expected.empty());
    // Live: the reader saw each model's table as the CLI's reply has it (same revision).
    std::map<std::string, nlohmann::json> live_tables;
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (live_tables.size() < expected.size() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(100ms);
      for (const auto& table : json_lines(read_file(live_file))) {
        const auto it = expected.find(table.at("model").get<std::string>());
        if (it != expected.end() && table.at("revision") == it->second.at("revision"))
          live_tables[table.at("model").get<std::string>()] = table;
      }
    }
    ASSERT_EQ(live_tables.size(), expected.size()) << read_file(live_file);
    for (const auto& [model, table] : expected) EXPECT_EQ(live_tables.at(model), table) << model;
  }
  // Late joiner: the server's durability delivers the latest table of every model.
  const auto expected = cli_tables("interop-car");
  const auto late = peer({"estimates", "--vehicle", "interop-car", "--models",
                          std::to_string(expected.size()), "--seconds", "20"});
  ASSERT_EQ(late.exit_code, 0) << late.err;
  std::map<std::string, nlohmann::json> late_tables;
  for (const auto& table : json_lines(late.out))
    late_tables[table.at("model").get<std::string>()] = table;
  ASSERT_EQ(late_tables.size(), expected.size());
  for (const auto& [model, table] : expected) EXPECT_EQ(late_tables.at(model), table) << model;
}

// (b) an `estimate` request from Fast DDS gets the reply dynid gets.
TEST_F(Interop, FastDdsRequestGetsTheReplyDynidGets) {
  ASSERT_TRUE(stream_with_test_car("request-car", "run-b"));
  for (const bool json : {true, false}) {
    std::vector<std::string> request{"request", "--kind", "estimate", "--arg",
                                     "vehicle=request-car"};
    std::vector<std::string> cli{"estimates", "--vehicle", "request-car"};
    if (json) {
      request.insert(request.end(), {"--arg", "format=json"});
      cli.insert(cli.begin(), "--json");
    }
    const auto reply = peer(request);
    const auto expected = run_dynid(cli);
    ASSERT_EQ(reply.exit_code, 0) << reply.err;
    ASSERT_EQ(expected.exit_code, 0) << expected.err;
    EXPECT_EQ(reply.err, "status OK\n");
    // dynid prints the payload, with a line end if it has none.
    const std::string payload =
        reply.out.empty() || reply.out.back() == '\n' ? reply.out : reply.out + "\n";
    EXPECT_EQ(payload, expected.out);
  }
  // A status other than OK, with its error text.
  const auto missing = peer({"request", "--kind", "estimate", "--arg", "vehicle=nobody"});
  const auto cli_missing = run_dynid({"estimates", "--vehicle", "nobody"});
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  EXPECT_NE(cli_missing.exit_code, 0);
  const std::string error =
      cli_missing.err.substr(cli_missing.err.find(": ") + 2);  // "dynid estimate: <error>"
  EXPECT_EQ(missing.err, "status NOT_FOUND: " + error);
}

// (c) a Fast DDS car: acknowledged and folded as TestCar's same chunks are.
TEST_F(Interop, FastDdsCarIsAcknowledgedAndFoldedAsTestCar) {
  ASSERT_TRUE(stream_with_test_car("cyclone-car", "run-c"));
  const std::string file = dir_.file("run.json");
  std::ofstream(file) << run_file(run_.announcement, chunks_).dump();
  const auto car = peer({"car", "--vehicle", "fastdds-car", "--run-file", file, "--seconds", "40"});
  ASSERT_EQ(car.exit_code, 0) << car.out << car.err;
  const auto ack = nlohmann::json::parse(car.out);
  EXPECT_EQ(ack.at("highest_contiguous"), static_cast<std::int64_t>(chunks_.size()) - 1);
  EXPECT_TRUE(ack.at("rejections").empty());

  // The server folds the Fast DDS car's run to the TestCar run's estimate, field by field but
  // for the vehicle and the revision (a count of that vehicle's publications).
  auto references_of_run = references(offline(run_, chunks_).estimates());
  EstimateWatcher watcher("fastdds-car");
  ASSERT_TRUE(watcher.wait_for(references_of_run, "run-c")) << watcher.seen();
  const auto from_cyclone = cli_tables("cyclone-car");
  const auto from_fastdds = cli_tables("fastdds-car");
  ASSERT_FALSE(from_fastdds.empty());
  ASSERT_EQ(from_fastdds.size(), from_cyclone.size());
  for (auto [model, table] : from_fastdds) {
    auto expected = from_cyclone.at(model);
    for (auto* t : {&table, &expected}) {
      t->erase("vehicle");
      t->erase("revision");
    }
    EXPECT_EQ(table, expected) << model;
  }
  for (const auto& reference : references_of_run)
    expect_equal(reference, watcher.latest("run-c").at(reference.model));
}

// Bad input from a foreign peer: a chunk with a wrong checksum is refused with the reason and
// changes nothing (the run stops before it); the same chunk sent right completes the run.
TEST_F(Interop, FastDdsCarsCorruptedChunkIsRefusedWithTheReason) {
  run_ = test_run("fastdds-bad", "run-d", 4u);
  chunks_ = cut_run(run_, 9u);
  const std::string file = dir_.file("run.json");
  std::ofstream(file) << run_file(run_.announcement, chunks_).dump();
  const std::vector<std::string> car{"car", "--vehicle", "fastdds-bad", "--run-file", file};
  auto corrupt = car;
  corrupt.insert(corrupt.end(), {"--corrupt", "2", "--seconds", "6"});
  const auto refused = peer(corrupt);
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  const auto ack = nlohmann::json::parse(refused.out);
  EXPECT_EQ(ack.at("highest_contiguous"), 1);
  ASSERT_FALSE(ack.at("rejections").empty()) << refused.out;
  EXPECT_EQ(ack["rejections"][0]["sequence_number"], 2);
  EXPECT_NE(ack["rejections"][0]["reason"].get<std::string>().find("checksum"), std::string::npos)
      << refused.out;

  auto right = car;
  right.insert(right.end(), {"--seconds", "40"});
  const auto completed = peer(right);
  ASSERT_EQ(completed.exit_code, 0) << completed.out << completed.err;
  EXPECT_EQ(nlohmann::json::parse(completed.out).at("highest_contiguous"),
            static_cast<std::int64_t>(chunks_.size()) - 1);
}

}  // namespace
}  // namespace dynid::e2e
