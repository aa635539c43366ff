#pragma once
// LeaseKeeper: which vehicles this server serves when several servers share one PostgreSQL
// store (issue 20; docs/DESIGN.md, "Scale-out"). A vehicle is served (its chunks stored,
// folded and acknowledged, its requests answered) by the server holding its lease in the
// database (store.hpp, Leases); the others stay silent, and the cars, which resend what is not
// acknowledged, need not know who that is.
//
// Contract:
// - The keeper talks to the database through a Store of its own (not fenced, not the workers'
//   SharedStore), so taking a lease never waits for a commit in progress, and the workers'
//   store, fenced by the same holder id, refuses every write once a lease is lost.
// - serves(v): `held` when this server holds v's lease (as of its last renewal, and that
//   renewal is less than a TTL old); else, when the lease is free or expired and taking it keeps
//   the share fair (below), it takes it: `taken`; else `other` (held elsewhere, or this
//   server's share is full). After `taken` the server must drop whatever it kept in memory of
//   the vehicle and load it from the store (checkpoint + the chunks after it) before folding
//   anything new: another server may have served it meanwhile. Whether the lease is free is
//   judged first on the lease table as read at most 500 ms ago (so a car's every chunk does not
//   cost a round trip to the database, and a server that stopped or joined shows within that),
//   then by the acquisition itself. A vehicle this server is giving back is not taken again
//   before its release.
// - Presence: a server is live while its heartbeat, a lease on the reserved name
//   "server:<id>" (':' is never in a vehicle id, input/ids.hpp), is unexpired. The keeper's
//   thread renews the heartbeat, then every lease it holds, every TTL/3, then reads the lease
//   table.
// - Fair share: with V vehicles (those with a live lease, and those asked about in the last
//   3 TTL: every server sees every car's samples) and S live servers (this one included), a
//   server takes a vehicle only while it holds fewer than ceil(V / S), and after a renewal it
//   gives back (sheds) the leases it holds above that, so a server that joins finds vehicles to
//   take. A dead server's heartbeat expires no later than its vehicles' leases (renewed
//   first), so the survivors' share grows as its vehicles free up.
// - Idle: a held vehicle nobody asked about (no sample, no request) for 3 TTL is given back
//   (shed) as well, so leases of cars that stopped are not renewed for ever.
// - A lease that a renewal finds lost (another holder took it after it expired) and a lease
//   shed are reported through `on_lost(vehicle, shed)` on the keeper's thread, after the
//   vehicle left the held set (serves() says `other` from then on). For a shed lease the
//   callback must settle the vehicle's writes and then call release(vehicle); for a lost one
//   drop it from memory without acknowledging anything more (its writes fail: NotHolderError).
// - forget(v): the workers found the lease lost on a write; v leaves the held set.
// - stop(): ends the renewals (idempotent; the destructor calls it). release_all() then gives
//   every lease and the heartbeat back at once, for a server stopping after its last
//   acknowledged write: the others take its vehicles over without waiting for the TTL.
// - leases(): the unexpired leases (vehicles and heartbeats), read from the database now, for
//   `dynid status`; StoreError when the database cannot be reached.
// Thread-safe.
#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "dynid/store/store.hpp"

namespace dynid::server {

/// The heartbeat's name in the lease table: "server:<id>".
std::string heartbeat_name(const std::string& server_id);
/// The server id a heartbeat names, or "" when `name` is a vehicle's.
std::string server_of_heartbeat(const std::string& name);

/// Server id -> the vehicles it holds, sorted, from unexpired `leases` (LeaseKeeper::leases()):
/// every server with a heartbeat, holding vehicles or not, and every holder of a vehicle.
std::map<std::string, std::vector<std::string>> holdings(const std::vector<store::Lease>& leases);

/// A share of `vehicles` among `servers` live servers: ceil(vehicles / servers), at least 1.
std::size_t fair_share(std::size_t vehicles, std::size_t servers);

class LeaseKeeper {
 public:
  enum class Serves { held, taken, other };
  /// Called on the keeper's thread; see the contract.
  using Lost = std::function<void(const std::string& vehicle, bool shed)>;

  /// Opens its own Store at `location` (unfenced), writes the heartbeat and starts renewing.
  LeaseKeeper(const std::string& location, store::StoreOptions options, std::string server_id,
              std::chrono::milliseconds ttl, Lost on_lost);
  LeaseKeeper(const LeaseKeeper&) = delete;
  LeaseKeeper& operator=(const LeaseKeeper&) = delete;
  ~LeaseKeeper();

  const std::string& server_id() const { return id_; }
  Serves serves(const std::string& vehicle);
  bool holds(const std::string& vehicle);
  void forget(const std::string& vehicle);
  void release(const std::string& vehicle);
  void stop();
  void release_all();
  std::vector<store::Lease> leases();

 private:
  using Clock = std::chrono::steady_clock;
  void run();
  void renew();
  /// Under mutex_: the vehicles idle or above the fair share, taken out of held_.
  std::vector<std::string> to_give_back();
  // Under mutex_:
  std::int64_t database_now() const;  // the database's clock, estimated from the last renewal
  std::size_t live_servers() const;
  bool held_elsewhere(const std::string& vehicle) const;  // by the table
  void refresh_table();  // read again when older than kTableMaxAge
  void remember(const store::Lease& lease);
  std::size_t vehicle_count() const;  // under mutex_

  const std::string id_;
  const std::chrono::milliseconds ttl_;
  const Lost on_lost_;
  std::mutex mutex_;  // everything below, and the store (one thread at a time)
  store::Store store_;
  std::map<std::string, Clock::time_point> held_;  // vehicle -> valid until (local clock)
  std::set<std::string> releasing_;  // given back, not yet released: not taken again before
  std::map<std::string, Clock::time_point> asked_;    // vehicle -> last asked about
  std::vector<store::Lease> table_;  // as last read (and as failed acquisitions found it)
  Clock::time_point table_at_;       // when it was read
  std::int64_t database_now_ns_ = 0;  // the database's clock at the last renewal
  Clock::time_point database_now_at_;  // when that was, on this machine's
  std::condition_variable stop_signal_;
  bool stopping_ = false;
  std::thread thread_;  // last: started once everything above exists
};

}  // namespace dynid::server
