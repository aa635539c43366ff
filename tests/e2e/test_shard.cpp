// Scale-out (docs/DESIGN.md, "Scale-out"): two dynid-server processes on one DDS domain,
// --shard 0/2 and 1/2, each on its own SQLite store, four vehicles two per shard streaming.
//
// - Every vehicle is acknowledged, stored and answered by its owner only; `dynid vehicles`
//   lists all four (both shards answered), `dynid estimates --vehicle v` answers for each v.
// - Server 1 is stopped twice in the middle of the runs, by SIGTERM and by SIGKILL. While it
//   is down, server 0's vehicles keep being acknowledged and their published estimates keep
//   up with what was sent (equal to the offline estimate of the prefix); server 1's cars keep
//   sending into the void and get no acknowledgement; `dynid vehicles` lists server 0's and
//   names shard 1/2 as missing (exit 6); a request for a vehicle of shard 1 says no server
//   of its shard answered (exit 5).
// - Restarted on its store, server 1 resumes its runs (checkpoint + stored chunks) and the
//   cars' resent chunks complete them.
// - After the runs are closed, every vehicle's final estimates equal those of the same runs
//   through one unsharded server to 1e-9 relative, and each store holds its own vehicles only.
// The servers run with deploy/cyclonedds/server-lease.xml (2 s lease): a killed server holds
// the cars' chunk writers until its lease expires (docs/DESIGN.md, "Scale-out").
#include <signal.h>
#include <sys/wait.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <memory>

#include "dynid/server/shard.hpp"
#include "dynid/store/store.hpp"
#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

constexpr std::uint32_t kShards = 2;

struct Vehicle {
  std::string id;
  std::uint32_t owner = 0;
  std::vector<ingest::Chunk> chunks;
  ingest::test::TestRun run;
  /// Where the phases of the main test cut this vehicle's chunks: before, during and after the
  /// SIGTERM outage, one chunk, during and after the SIGKILL outage.
  std::size_t mark(std::size_t phase) const {
    const std::size_t n = chunks.size();
    const std::size_t marks[] = {0, n / 4, n / 2, n / 2 + 1, 3 * n / 4, n};
    return marks[phase];
  }
  std::unique_ptr<TestCar> car;
  std::unique_ptr<EstimateWatcher> watcher;
};

std::vector<Vehicle> fleet(const std::string& run_id) {
  std::vector<Vehicle> vehicles;
  for (unsigned k = 0; k < 4; ++k) {
    Vehicle v;
    v.id = "shard-car-" + std::to_string(k);
    v.owner = server::Shard::owner_of(v.id, kShards);
    v.run = test_run(v.id, run_id, 60u + k);
    v.chunks = cut_run(v.run, 70u + k, 500);
    vehicles.push_back(std::move(v));
  }
  return vehicles;
}

void connect(std::vector<Vehicle>& vehicles) {
  for (auto& v : vehicles) {
    v.car = std::make_unique<TestCar>(v.id);
    v.watcher = std::make_unique<EstimateWatcher>(v.id);
    v.car->announce(v.run.announcement);
  }
}

// The offline estimates of the first `end` chunks; of the whole run closed when `closed`.
std::vector<Reference> expected(const Vehicle& v, std::size_t end, bool closed = false) {
  const std::vector<ingest::Chunk> prefix(v.chunks.begin(),
                                          v.chunks.begin() + static_cast<std::ptrdiff_t>(end));
  auto processor = offline(v.run, prefix);
  if (closed) processor.finish();
  return references(processor.estimates());
}

bool published(Vehicle& v, const std::vector<Reference>& references) {
  return v.watcher->wait_for(references, v.run.announcement.run);
}

// Closed by its owner: shard `owner` of `count` (0 of 0 for one server that does not say).
void close_run(const Vehicle& v, std::uint32_t owner, std::uint32_t count) {
  const auto reply = request("close", {{"vehicle", v.id}, {"run", v.run.announcement.run}});
  ASSERT_EQ(reply.status, dds::ReplyStatus::kOk) << v.id << ": " << reply.error;
  EXPECT_EQ(reply.shard, owner) << "close of " << v.id << " answered by another shard";
  EXPECT_EQ(reply.shard_count, count);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class ShardServer {
 public:
  ShardServer(const TempDir& dir, std::uint32_t index) : dir_(dir), index_(index) { start(); }
  void start() {
    process_ = std::make_unique<ServerProcess>(
        std::vector<std::string>{"--store", store(), "--cyclone-config", server_config(), "--domain",
                                 std::to_string(kDomain), "--shard",
                                 std::to_string(index_) + "/" + std::to_string(kShards), "--threads", "1",
                                 "--checkpoint-every", "3", "--publish-interval-ms", "20", "--log-level",
                                 "info"},
        log());
  }
  /// Sends `signal` and waits for the exit; true when it ended as that signal should end it.
  bool stop(int signal) {
    process_->signal(signal);
    const auto status = process_->wait(15s);
    process_.reset();
    if (!status) return false;
    return signal == SIGKILL ? WIFSIGNALED(*status) && WTERMSIG(*status) == SIGKILL
                             : WIFEXITED(*status) && WEXITSTATUS(*status) == 0;
  }
  std::string store() const { return dir_.file("shard" + std::to_string(index_) + ".db"); }
  std::string log() const { return dir_.file("shard" + std::to_string(index_) + ".log"); }
  std::string log_text() const { return read_text(log()); }

 private:
  const TempDir& dir_;
  std::uint32_t index_;
  std::unique_ptr<ServerProcess> process_;
};

CommandResult dynid(const std::vector<std::string>& arguments, int timeout_s = 10) {
  std::vector<std::string> argv{DYNID_CLI_EXE, "--cyclone-config", loopback_config(), "--domain",
                                std::to_string(kDomain), "--timeout", std::to_string(timeout_s)};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return run_command(argv, std::chrono::seconds(timeout_s + 10));
}

// The same runs through one server owning every vehicle: the final tables per vehicle.
std::map<std::string, std::map<std::string, dds::EstimateTable>> single_server_reference(const TempDir& dir) {
  std::map<std::string, std::map<std::string, dds::EstimateTable>> out;
  InProcessServer single(server_options(dir.file("single.db")));
  auto vehicles = fleet("ref");
  connect(vehicles);
  for (auto& v : vehicles) EXPECT_TRUE(v.car->deliver(v.chunks)) << v.id;
  for (auto& v : vehicles) {
    close_run(v, 0, 1);
    EXPECT_TRUE(published(v, expected(v, v.chunks.size(), true))) << v.id;
    out[v.id] = v.watcher->latest(v.run.announcement.run);
  }
  return out;
}

void expect_same_tables(const dds::EstimateTable& sharded, const dds::EstimateTable& single) {
  const auto same = [](double a, double b) {
    return (std::isnan(a) && std::isnan(b)) || std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
  };
  const std::string what = sharded.vehicle + " " + sharded.model;
  ASSERT_EQ(sharded.parameters.size(), single.parameters.size()) << what;
  EXPECT_EQ(sharded.rows, single.rows) << what;
  EXPECT_TRUE(same(sharded.sigma, single.sigma)) << what << " sigma";
  for (std::size_t j = 0; j < single.parameters.size(); ++j) {
    const auto& a = sharded.parameters[j];
    const auto& b = single.parameters[j];
    EXPECT_EQ(a.name, b.name) << what;
    EXPECT_TRUE(same(a.value, b.value)) << what << "." << a.name << ": " << a.value << " vs " << b.value;
    EXPECT_TRUE(same(a.standard_deviation, b.standard_deviation))
        << what << "." << a.name << " std: " << a.standard_deviation << " vs " << b.standard_deviation;
  }
}

// Every vehicle of `owner` (all when nullopt) sends its chunks of `phase` and has them
// acknowledged.
void deliver_phase(std::vector<Vehicle>& vehicles, std::size_t phase, const ShardServer& server,
                   std::optional<std::uint32_t> owner = std::nullopt) {
  for (auto& v : vehicles)
    if (!owner || v.owner == *owner) {
      ASSERT_TRUE(v.car->deliver(v.chunks, v.mark(phase), v.mark(phase + 1)))
          << v.id << ": chunks " << v.mark(phase) << ".." << v.mark(phase + 1) << " not acknowledged\n"
          << server.log_text();
    }
}

// Server 1 is down during `phase`: server 0's vehicles get their chunks acknowledged and their
// estimates follow; server 1's cars send theirs and hear nothing.
void outage(std::vector<Vehicle>& vehicles, std::size_t phase, const ShardServer& zero) {
  for (auto& v : vehicles)
    if (v.owner == 1)
      for (std::size_t k = v.mark(phase); k < v.mark(phase + 1); ++k) v.car->send(v.chunks[k]);  // unheard
  deliver_phase(vehicles, phase, zero, 0);
  for (auto& v : vehicles) {
    if (v.owner != 0) continue;
    EXPECT_TRUE(published(v, expected(v, v.mark(phase + 1)))) << v.id << ": estimates did not follow during the outage";
  }
  for (auto& v : vehicles) {
    if (v.owner != 1) continue;
    const auto from = static_cast<std::int64_t>(v.mark(phase));
    const auto receipt = v.car->wait_receipt(
        v.run.announcement.run, [&](const dds::ChunkReceipt& r) { return r.highest_contiguous >= from; }, 200ms);
    ASSERT_TRUE(receipt.has_value());
    EXPECT_EQ(receipt->highest_contiguous, from - 1) << v.id << " acknowledged while its server was down";
  }
}

TEST(E2eShard, TwoServersOwnTheirVehiclesAndOneStoppingDisturbsNotTheOther) {
  TempDir dir;
  const auto single = single_server_reference(dir);
  ASSERT_EQ(single.size(), 4u);

  auto vehicles = fleet("run");
  std::size_t owned_by_one = 0;
  for (const auto& v : vehicles) owned_by_one += v.owner;
  ASSERT_EQ(owned_by_one, 2u) << "the test needs two vehicles on each shard";
  for (const auto& v : vehicles) ASSERT_GE(v.chunks.size(), 12u);

  ShardServer zero(dir, 0), one(dir, 1);
  connect(vehicles);
  deliver_phase(vehicles, 0, zero, 0);
  deliver_phase(vehicles, 0, one, 1);

  // Both up: the CLI lists every vehicle; each vehicle's requests are its owner's.
  const auto listed = dynid({"vehicles"});
  EXPECT_EQ(listed.exit_code, 0) << listed.err;
  EXPECT_EQ(listed.out, "shard-car-0\nshard-car-1\nshard-car-2\nshard-car-3\n") << listed.err;
  for (auto& v : vehicles) {
    const auto table = dynid({"estimates", "--vehicle", v.id});
    EXPECT_EQ(table.exit_code, 0) << table.err;
    EXPECT_NE(table.out.find(v.id + " / longitudinal_wheel"), std::string::npos) << table.out;
    const auto reply = request("estimate", {{"vehicle", v.id}});
    EXPECT_EQ(reply.status, dds::ReplyStatus::kOk) << reply.error;
    EXPECT_EQ(reply.shard, v.owner) << v.id;
    EXPECT_EQ(reply.shard_count, kShards);
  }
  const auto status = dynid({"--json", "status"});
  EXPECT_EQ(status.exit_code, 0) << status.err;
  EXPECT_NE(status.out.find("\"shards\":{\"0/2\":{"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("\"1/2\":{"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("\"missing\":[]"), std::string::npos) << status.out;

  // Outage 1: SIGTERM.
  ASSERT_TRUE(one.stop(SIGTERM)) << one.log_text();
  outage(vehicles, 1, zero);
  const auto partial = dynid({"vehicles"}, 2);
  EXPECT_EQ(partial.exit_code, 6) << partial.err;
  EXPECT_EQ(partial.out, "shard-car-1\nshard-car-3\n");
  EXPECT_NE(partial.err.find("shard 1/2 did not answer within 2000 ms"), std::string::npos) << partial.err;
  const auto orphan = dynid({"estimates", "--vehicle", "shard-car-0"}, 2);
  EXPECT_EQ(orphan.exit_code, 5) << orphan.err;
  EXPECT_NE(orphan.err.find("for vehicle shard-car-0"), std::string::npos) << orphan.err;
  one.start();
  deliver_phase(vehicles, 1, one, 1);  // resumed from its store, the rest resent by the cars
  EXPECT_NE(one.log_text().find("resuming 2 open runs"), std::string::npos) << one.log_text();

  // Outage 2: SIGKILL, nothing flushed on the way out.
  deliver_phase(vehicles, 2, zero, 0);
  deliver_phase(vehicles, 2, one, 1);
  ASSERT_TRUE(one.stop(SIGKILL));
  outage(vehicles, 3, zero);
  one.start();
  deliver_phase(vehicles, 3, one, 1);

  // Both up to the end; the runs closed by their owners; final estimates = one server's.
  deliver_phase(vehicles, 4, zero, 0);
  deliver_phase(vehicles, 4, one, 1);
  for (auto& v : vehicles) {
    close_run(v, v.owner, kShards);
    ASSERT_TRUE(published(v, expected(v, v.chunks.size(), true))) << v.id << "\n" << (v.owner ? one : zero).log_text();
    for (const auto& [model, table] : single.at(v.id)) {
      ASSERT_TRUE(v.watcher->latest(v.run.announcement.run).count(model)) << v.id << " " << model;
      expect_same_tables(v.watcher->latest(v.run.announcement.run).at(model), table);
    }
    EXPECT_EQ(v.watcher->foreign(), 0u);
  }
  ASSERT_TRUE(zero.stop(SIGTERM)) << zero.log_text();
  ASSERT_TRUE(one.stop(SIGTERM)) << one.log_text();
  EXPECT_EQ(one.log_text().find("folded twice"), std::string::npos);

  // Each store holds its own vehicles, every chunk of their runs.
  for (std::uint32_t k = 0; k < kShards; ++k) {
    store::Store store(dir.file("shard" + std::to_string(k) + ".db"));
    std::vector<std::string> own;
    for (const auto& v : vehicles)
      if (v.owner == k) {
        own.push_back(v.id);
        EXPECT_EQ(store.highest_contiguous({v.id, "run"}), v.chunks.size() - 1) << v.id;
      }
    EXPECT_EQ(store.list_vehicles(), own) << "store of shard " << k;
  }
}

TEST(E2eShard, AServerRefusesAStoreOfAnotherShardAndAFleetSpanningShards) {
  TempDir dir;
  {
    InProcessServer single(server_options(dir.file("one.db")));
    auto vehicles = fleet("run");
    connect(vehicles);
    for (auto& v : vehicles) ASSERT_TRUE(v.car->deliver(v.chunks, 0, 2)) << v.id;
  }
  auto options = server_options(dir.file("one.db"));
  options.shard = server::Shard::parse("1/2");
  try {
    server::Server refused(options);
    ADD_FAILURE() << "a store holding shard 0's vehicles was served as shard 1/2";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("holds 2 vehicle(s) of other shards: shard-car-1 (shard 0)"),
              std::string::npos)
        << e.what();
  }

  // A fleet over both shards: the owners refuse it the same way, saying who serves what.
  auto zero = server_options(dir.file("zero.db"));
  zero.shard = server::Shard::parse("0/2");
  InProcessServer running(zero);
  const auto spanning = request("fleet", {{"model", "longitudinal_wheel"}, {"shared", "scx"},
                                          {"vehicles", "shard-car-0,shard-car-1"}});
  EXPECT_EQ(spanning.status, dds::ReplyStatus::kBadRequest);
  EXPECT_NE(spanning.error.find("(shard-car-1 on shard 0/2; shard-car-0 on shard 1/2)"), std::string::npos)
      << spanning.error;
}

}  // namespace
}  // namespace dynid::e2e
