// Cluster (issue 20; docs/DESIGN.md, "Scale-out"): dynid-server processes sharing one
// PostgreSQL store (a real server the test starts, tests/store/postgres_cluster.hpp), vehicles
// served under leases (server/lease_keeper.hpp), cars streaming from this process on loopback.
//
// The cars here are the e2e TestCar driven as dynid-car drives its spool: a new chunk at the
// run's pace while fewer than kWindow are unacknowledged, and everything unacknowledged sent
// again after kResendAfter without progress (dynid-car --ack-timeout 1).
//
// - SigkilledServersVehiclesMoveWithinBound: three servers, kVehicles vehicles. One server is
//   killed (SIGKILL) mid-run. Each of its vehicles is acknowledged again within
//   kTakeoverBound of the kill (p99 printed), now by a live server (the lease table says
//   which). Every run ends stored once (the ledger: contiguous and folded through its last
//   chunk, one row per chunk) and its published estimates equal those of one processor fed the
//   same chunks in one go.
// - SigtermHandsOverAtOnceAndJoinerTakesShare: with a long TTL (kLongTtl), a server stopped with
//   SIGTERM releases its leases: its vehicles are acknowledged by the others well before the
//   TTL could have expired. A server started mid-run then takes vehicles (the others give back
//   what is above the fair share) and acknowledges them; `dynid status` (text and --json) lists
//   the live servers, the joiner among them, and not the stopped one.
//
// kVehicles is 30, as in issue 20, with runs of ~60 chunks over 30 s (50 s in the second test,
// so that the runs are still going when the fourth server joins).
#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <deque>
#include <fstream>
#include <memory>
#include <set>

#include <nlohmann/json.hpp>

#include "dynid/store/store.hpp"
#include "e2e_fixture.hpp"
#include "postgres_cluster.hpp"

namespace dynid::e2e {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kVehicles = 30;
constexpr std::size_t kWindow = 8;
constexpr auto kResendAfter = 1s;
constexpr auto kTtl = 2s;
constexpr auto kLongTtl = 20s;
// From the kill to the new holder's first acknowledgement: the TTL, a renewal period to see
// the dead server's heartbeat gone, a resend, and a margin for a loaded machine (5 s).
constexpr auto kTakeoverBound = kTtl + 5s;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

struct Car {
  std::string id;
  ingest::test::TestRun run;
  std::vector<ingest::Chunk> chunks;
  std::unique_ptr<TestCar> car;
  std::unique_ptr<EstimateWatcher> watcher;
  Clock::time_point start;        // when chunk 0 is due
  Clock::duration period{};       // between two new chunks
  std::size_t sent = 0;           // chunks sent at least once
  std::int64_t acked = -1;        // highest contiguous acknowledged
  Clock::time_point progress;     // last time `acked` grew (or a resend)
  std::vector<Clock::time_point> receipts;  // when each receipt arrived

  bool done() const { return acked + 1 == static_cast<std::int64_t>(chunks.size()); }
  /// The first receipt at or after `t`, if any.
  std::optional<Clock::time_point> first_receipt_after(Clock::time_point t) const {
    const auto it = std::lower_bound(receipts.begin(), receipts.end(), t);
    return it == receipts.end() ? std::nullopt : std::optional(*it);
  }
};

class Cluster {
 public:
  Cluster(std::chrono::seconds ttl, Clock::duration run_time)
      : uri_(store::test::cluster().fresh_store("cluster")), reader_(uri_), ttl_(ttl), run_time_(run_time) {
    for (std::size_t k = 0; k < kVehicles; ++k) {
      Car c;
      c.id = "cluster-car-" + std::to_string(k);
      c.run = test_run(c.id, "run-c", 100u + static_cast<unsigned>(k));
      c.chunks = cut_run(c.run, 200u + static_cast<unsigned>(k), 200);
      c.car = std::make_unique<TestCar>(c.id);
      c.watcher = std::make_unique<EstimateWatcher>(c.id);
      cars_.push_back(std::move(c));
    }
  }

  std::size_t start_server() {
    const std::size_t k = servers_.size();
    ids_.push_back("server-" + std::to_string(k));
    servers_.push_back(std::make_unique<ServerProcess>(
        std::vector<std::string>{"--store", uri_, "--cyclone-config", server_config(), "--domain",
                                 std::to_string(domain()), "--threads", "1", "--checkpoint-every",
                                 "5", "--publish-interval-ms", "200", "--server-id", ids_[k],
                                 "--lease-ttl", std::to_string(ttl_.count()), "--log-level", "info"},
        dir_.file(ids_[k] + ".log")));
    return k;
  }
  ServerProcess& server(std::size_t k) { return *servers_[k]; }
  const std::string& id(std::size_t k) const { return ids_[k]; }
  std::vector<Car>& cars() { return cars_; }

  void announce_all() {
    const auto now = Clock::now();
    for (std::size_t k = 0; k < cars_.size(); ++k) {
      Car& c = cars_[k];
      c.car->announce(c.run.announcement);
      c.period = run_time_ / c.chunks.size();
      c.start = now + c.period * k / cars_.size();  // spread over one period
      c.progress = now;
    }
  }

  /// Three servers, the cars announced, driven until each server holds vehicles, then `more`.
  bool start_three(Clock::duration more) {
    for (int k = 0; k < 3; ++k) start_server();
    announce_all();
    if (!wait_until_each_holds({id(0), id(1), id(2)}, 30s)) return false;
    drive(more);
    return true;
  }
  /// The vehicles server k holds, after one round of the cars: the receipts taken now, anything
  /// taken later arrived later (when server k is stopped right after).
  std::set<std::string> held_by(std::size_t k) {
    for (Car& c : cars_) step(c);
    std::set<std::string> vehicles;
    for (const auto& [vehicle, holder] : holders())
      if (holder == id(k)) vehicles.insert(vehicle);
    for (Car& c : cars_) step(c);
    return vehicles;
  }

  /// Drives every car for `how_long` (or until all are acknowledged through their last chunk).
  void drive(Clock::duration how_long) {
    const auto end = Clock::now() + how_long;
    while (Clock::now() < end && !all_done()) {
      for (Car& c : cars_) step(c);
      std::this_thread::sleep_for(10ms);
    }
  }
  bool all_done() const {
    return std::all_of(cars_.begin(), cars_.end(), [](const Car& c) { return c.done(); });
  }

  /// Vehicle -> holder of its unexpired lease, from the database.
  std::map<std::string, std::string> holders() {
    std::map<std::string, std::string> out;
    const auto now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
    // The database runs on this machine: its clock is this one.
    for (const auto& lease : reader_.leases())
      if (lease.expires_ns > now && lease.vehicle.rfind("server:", 0) != 0) out[lease.vehicle] = lease.holder;
    return out;
  }
  /// Waits (driving the cars) until every server in `expected` holds at least one vehicle.
  bool wait_until_each_holds(const std::set<std::string>& expected, Clock::duration patience) {
    const auto end = Clock::now() + patience;
    while (Clock::now() < end) {
      drive(500ms);
      std::set<std::string> holding;
      for (const auto& [vehicle, holder] : holders()) holding.insert(holder);
      if (std::includes(holding.begin(), holding.end(), expected.begin(), expected.end())) return true;
    }
    return false;
  }

  /// The servers' log lines about leases, errors and warnings (the last 40 of each).
  std::string logs() const {
    std::string all;
    for (const auto& id : ids_) {
      std::ifstream in(dir_.file(id + ".log"));
      std::deque<std::string> kept;
      for (std::string line; std::getline(in, line);) {
        if (line.find("lease") == std::string::npos && line.find("error") == std::string::npos &&
            line.find("warn") == std::string::npos)
          continue;
        kept.push_back(line);
        if (kept.size() > 40) kept.pop_front();
      }
      all += "---- " + id + "\n";
      for (const auto& line : kept) all += line + "\n";
    }
    return all;
  }

  /// Every run stored once and folded through its end; its estimates as one processor's.
  void expect_complete_and_exact() {
    store::Store& reader = reader_;
    for (Car& c : cars_) {
      const store::RunKey key{c.id, "run-c"};
      const auto last = c.chunks.size() - 1;
      EXPECT_EQ(reader.highest_contiguous(key), last) << c.id;
      const auto runs = reader.list_runs(c.id);
      ASSERT_EQ(runs.size(), 1u) << c.id;
      EXPECT_EQ(runs[0].chunks_stored, c.chunks.size()) << c.id << ": a chunk stored twice or lost";
      std::size_t k = 0;
      auto stream = reader.chunks(key, 0, last);
      while (auto chunk = stream.next()) {
        ASSERT_LT(k, c.chunks.size());
        EXPECT_EQ(ingest::encode_chunk(*chunk), ingest::encode_chunk(c.chunks[k])) << c.id << "#" << k;
        ++k;
      }
      EXPECT_EQ(k, c.chunks.size()) << c.id;
      const auto expected = references(offline(c.run, c.chunks).estimates());
      ASSERT_TRUE(c.watcher->wait_for(expected, "run-c")) << c.id << "\n" << c.watcher->seen();
      // 0: bit for bit (NaN matches NaN), whichever servers folded which part of the run.
      for (const auto& reference : expected)
        expect_equal(reference, c.watcher->latest("run-c").at(reference.model), 0.0);
      EXPECT_EQ(reader.folded_through(key), last) << c.id << ": the ledger's folded mark";
    }
  }

 private:
  void step(Car& c) {
    const auto now = Clock::now();
    for (const auto& receipt : c.car->take_receipts()) {
      if (receipt.run != "run-c") continue;
      c.receipts.push_back(now);
      if (receipt.highest_contiguous > c.acked) {
        c.acked = receipt.highest_contiguous;
        c.progress = now;
      }
    }
    const auto in_flight = [&] { return static_cast<std::int64_t>(c.sent) - (c.acked + 1); };
    if (in_flight() > 0 && now - c.progress >= kResendAfter) {  // as the car's spool does
      for (auto k = static_cast<std::size_t>(c.acked + 1); k < c.sent; ++k) c.car->send(c.chunks[k]);
      c.progress = now;
    }
    while (c.sent < c.chunks.size() && now >= c.start + c.period * c.sent &&
           in_flight() < static_cast<std::int64_t>(kWindow))
      c.car->send(c.chunks[c.sent++]);
  }

  TempDir dir_;
  std::string uri_;
  store::Store reader_;  // the test's own connection (opened before any server)
  std::chrono::seconds ttl_;
  Clock::duration run_time_;
  std::vector<std::string> ids_;
  std::vector<std::unique_ptr<ServerProcess>> servers_;
  std::vector<Car> cars_;
};

TEST(Cluster, SigkilledServersVehiclesMoveWithinBound) {
  Cluster cluster(std::chrono::duration_cast<std::chrono::seconds>(kTtl), 30s);
  ASSERT_TRUE(cluster.start_three(3s)) << cluster.logs();  // well into the runs, shares taken

  const std::set<std::string> victims = cluster.held_by(2);
  ASSERT_FALSE(victims.empty());
  cluster.server(2).signal(SIGKILL);
  const auto killed = Clock::now();
  ASSERT_TRUE(cluster.server(2).wait(10s)) << "the server did not die of SIGKILL";

  cluster.drive(70s);
  ASSERT_TRUE(cluster.all_done()) << cluster.logs();

  std::vector<double> takeover;
  for (const Car& c : cluster.cars()) {
    if (!victims.contains(c.id)) continue;
    const auto first = c.first_receipt_after(killed);
    ASSERT_TRUE(first) << c.id << " never acknowledged after the kill";
    takeover.push_back(seconds(*first - killed));
  }
  std::sort(takeover.begin(), takeover.end());
  const double p99 = takeover[std::min(takeover.size() - 1, takeover.size() * 99 / 100)];
  std::printf("takeover of %zu vehicles after SIGKILL: min %.2f s, p99 %.2f s, max %.2f s (TTL %.1f s)\n",
              takeover.size(), takeover.front(), p99, takeover.back(), seconds(kTtl));
  EXPECT_LE(p99, seconds(kTakeoverBound)) << cluster.logs();

  for (const auto& [vehicle, holder] : cluster.holders())
    EXPECT_NE(holder, cluster.id(2)) << vehicle << " still held by the killed server";
  cluster.expect_complete_and_exact();
}

TEST(Cluster, SigtermHandsOverAtOnceAndJoinerTakesShare) {
  Cluster cluster(std::chrono::duration_cast<std::chrono::seconds>(kLongTtl), 50s);
  ASSERT_TRUE(cluster.start_three(2s)) << cluster.logs();

  const std::set<std::string> handed = cluster.held_by(2);
  ASSERT_FALSE(handed.empty());
  cluster.server(2).signal(SIGTERM);
  const auto stopped = Clock::now();
  const auto status = cluster.server(2).wait(10s);
  ASSERT_TRUE(status && WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << cluster.logs();
  cluster.drive(6s);
  double slowest = 0;
  for (const Car& c : cluster.cars()) {
    if (!handed.contains(c.id) || c.done()) continue;
    const auto first = c.first_receipt_after(stopped);
    ASSERT_TRUE(first) << c.id << " not acknowledged within 6 s of SIGTERM (TTL "
                       << seconds(kLongTtl) << " s)\n" << cluster.logs();
    slowest = std::max(slowest, seconds(*first - stopped));
  }
  std::printf("handover of %zu vehicles after SIGTERM: slowest %.2f s (TTL %.1f s)\n", handed.size(),
              slowest, seconds(kLongTtl));
  EXPECT_LT(slowest, seconds(kLongTtl) / 4);

  const std::size_t joiner = cluster.start_server();
  ASSERT_TRUE(cluster.wait_until_each_holds({cluster.id(joiner)}, 20s)) << cluster.logs();

  // `dynid status`: who holds which vehicle, as the database says.
  const auto answer = run_dynid({"status", "--json"});
  ASSERT_EQ(answer.exit_code, 0) << answer.err;
  const auto json = nlohmann::json::parse(answer.out);
  std::map<std::string, std::size_t> listed;
  for (const auto& server : json.at("servers")) listed[server.at("id").get<std::string>()] = server.at("vehicles").size();
  for (const std::size_t k : {std::size_t{0}, std::size_t{1}, joiner}) EXPECT_TRUE(listed.contains(cluster.id(k))) << answer.out;
  EXPECT_FALSE(listed.contains(cluster.id(2))) << "the stopped server is listed\n" << answer.out;
  const auto text = run_dynid({"status"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("SERVER"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find(cluster.id(joiner)), std::string::npos) << text.out;

  cluster.drive(70s);
  ASSERT_TRUE(cluster.all_done()) << cluster.logs();
  cluster.expect_complete_and_exact();
}

}  // namespace
}  // namespace dynid::e2e
