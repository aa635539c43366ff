// LeaseKeeper: leases, presence and the fair share (contract in lease_keeper.hpp).
#include "dynid/server/lease_keeper.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include <dynid/input/ids.hpp>

namespace dynid::server {

namespace {

constexpr std::string_view kHeartbeatPrefix = "server:";
// How old the lease table may be when a vehicle not held here is asked about: a server that
// stopped (its rows deleted) or joined shows within this, not a renewal period later.
constexpr auto kTableMaxAge = std::chrono::milliseconds(500);

std::int64_t to_ns(std::chrono::milliseconds d) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count();
}

}  // namespace

std::string heartbeat_name(const std::string& server_id) {
  return std::string(kHeartbeatPrefix) + server_id;
}

std::string server_of_heartbeat(const std::string& name) {
  return name.starts_with(kHeartbeatPrefix) ? name.substr(kHeartbeatPrefix.size()) : "";
}

std::map<std::string, std::vector<std::string>> holdings(const std::vector<store::Lease>& leases) {
  std::map<std::string, std::vector<std::string>> by_server;
  for (const auto& lease : leases) {
    const std::string server = server_of_heartbeat(lease.vehicle);
    auto& vehicles = by_server[server.empty() ? lease.holder : server];
    if (server.empty()) vehicles.push_back(lease.vehicle);
  }
  for (auto& [server, vehicles] : by_server) std::sort(vehicles.begin(), vehicles.end());
  return by_server;
}

std::size_t fair_share(std::size_t vehicles, std::size_t servers) {
  const std::size_t s = std::max<std::size_t>(servers, 1);
  return std::max<std::size_t>((vehicles + s - 1) / s, 1);
}

LeaseKeeper::LeaseKeeper(const std::string& location, store::StoreOptions options,
                         std::string server_id, std::chrono::milliseconds ttl, Lost on_lost)
    : id_(std::move(server_id)),
      ttl_(ttl),
      on_lost_(std::move(on_lost)),
      store_(location, [&] {
        options.holder.clear();  // the keeper's own reads and leases are never fenced
        return options;
      }()) {
  renew();  // the heartbeat is written before the first vehicle is asked about
  thread_ = std::thread([this] { run(); });
}

LeaseKeeper::~LeaseKeeper() { stop(); }

void LeaseKeeper::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_signal_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void LeaseKeeper::run() {
  std::unique_lock lock(mutex_);
  while (!stop_signal_.wait_for(lock, ttl_ / 3, [this] { return stopping_; })) {
    lock.unlock();
    try {
      renew();
    } catch (const std::exception& e) {  // the database unreachable: leases lapse, writes fail
      spdlog::error("leases of {} not renewed: {}", input::printable(id_), e.what());
    }
    lock.lock();
  }
}

void LeaseKeeper::renew() {
  std::vector<std::pair<std::string, bool>> gone;  // vehicle, shed
  {
    std::lock_guard lock(mutex_);
    const auto now = Clock::now();  // before the database's: the local deadline errs early
    database_now_ns_ = store_.acquire_lease(heartbeat_name(id_), id_, ttl_).expires_ns - to_ns(ttl_);
    database_now_at_ = now;
    for (auto it = held_.begin(); it != held_.end();) {
      if (store_.acquire_lease(it->first, id_, ttl_).holder == id_) {
        (it++)->second = now + ttl_;
      } else {
        gone.emplace_back(it->first, false);
        it = held_.erase(it);
      }
    }
    table_ = store_.leases();
    table_at_ = now;
    std::erase_if(asked_, [&](const auto& entry) { return now - entry.second > 3 * ttl_; });
    for (auto& vehicle : to_give_back()) gone.emplace_back(std::move(vehicle), true);
  }
  for (const auto& [vehicle, shed] : gone) {
    spdlog::info("vehicle {}: lease {}", input::printable(vehicle), shed ? "given back (idle or above the fair share)" : "lost");
    on_lost_(vehicle, shed);
  }
}

// Idle vehicles first (no sample nor request in 3 TTL: their leases would otherwise be renewed
// for ever), then those above the fair share.
std::vector<std::string> LeaseKeeper::to_give_back() {
  std::vector<std::string> shed;
  for (auto it = held_.begin(); it != held_.end();) {
    if (asked_.contains(it->first)) {
      ++it;
      continue;
    }
    shed.push_back(it->first);
    releasing_.insert(it->first);
    it = held_.erase(it);
  }
  const std::size_t share = fair_share(vehicle_count(), live_servers());
  while (held_.size() > share) {
    const auto last = std::prev(held_.end());
    shed.push_back(last->first);
    releasing_.insert(last->first);
    held_.erase(last);
  }
  return shed;
}

std::int64_t LeaseKeeper::database_now() const {
  return database_now_ns_ +
         std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - database_now_at_).count();
}

std::size_t LeaseKeeper::live_servers() const {
  std::set<std::string> live{id_};
  const std::int64_t now = database_now();
  for (const auto& lease : table_) {
    const std::string server = server_of_heartbeat(lease.vehicle);
    if (!server.empty() && lease.expires_ns > now) live.insert(server);
  }
  return live.size();
}

bool LeaseKeeper::held_elsewhere(const std::string& vehicle) const {
  const auto it = std::find_if(table_.begin(), table_.end(),
                               [&](const store::Lease& lease) { return lease.vehicle == vehicle; });
  return it != table_.end() && it->holder != id_ && it->expires_ns > database_now();
}

void LeaseKeeper::refresh_table() {
  if (Clock::now() - table_at_ < kTableMaxAge) return;
  table_ = store_.leases();
  table_at_ = Clock::now();
}

// What an acquisition that failed found: the lease as it stands, until the next read.
void LeaseKeeper::remember(const store::Lease& lease) {
  const auto it = std::find_if(table_.begin(), table_.end(),
                               [&](const store::Lease& l) { return l.vehicle == lease.vehicle; });
  if (it == table_.end()) {
    table_.push_back(lease);
  } else {
    *it = lease;
  }
}

// Every server sees every vehicle's samples: the vehicles asked about lately (a lease given
// back is deleted, but its car goes on sending) and those whose lease is live.
std::size_t LeaseKeeper::vehicle_count() const {
  std::set<std::string> vehicles;
  for (const auto& [vehicle, when] : asked_) vehicles.insert(vehicle);
  const std::int64_t now = database_now();
  for (const auto& lease : table_)
    if (server_of_heartbeat(lease.vehicle).empty() && lease.expires_ns > now) vehicles.insert(lease.vehicle);
  return vehicles.size();
}

LeaseKeeper::Serves LeaseKeeper::serves(const std::string& vehicle) {
  std::lock_guard lock(mutex_);
  const auto now = Clock::now();
  asked_[vehicle] = now;
  if (const auto it = held_.find(vehicle); it != held_.end() && now < it->second) return Serves::held;
  if (releasing_.contains(vehicle)) return Serves::other;  // still ours in the database
  // A lease that lapsed here (renewals late) counts as not held: it is taken again as new.
  held_.erase(vehicle);
  try {
    refresh_table();
    if (held_elsewhere(vehicle) || held_.size() >= fair_share(vehicle_count(), live_servers()))
      return Serves::other;
    const store::Lease lease = store_.acquire_lease(vehicle, id_, ttl_);
    if (lease.holder != id_) {
      remember(lease);
      return Serves::other;
    }
  } catch (const std::exception& e) {
    spdlog::error("vehicle {}: lease not taken: {}", input::printable(vehicle), e.what());
    return Serves::other;
  }
  held_[vehicle] = now + ttl_;
  spdlog::info("vehicle {}: lease taken by {} ({} held)", input::printable(vehicle),
               input::printable(id_), held_.size());
  return Serves::taken;
}

bool LeaseKeeper::holds(const std::string& vehicle) {
  std::lock_guard lock(mutex_);
  const auto it = held_.find(vehicle);
  return it != held_.end() && Clock::now() < it->second;
}

void LeaseKeeper::forget(const std::string& vehicle) {
  std::lock_guard lock(mutex_);
  held_.erase(vehicle);
}

void LeaseKeeper::release(const std::string& vehicle) {
  std::lock_guard lock(mutex_);
  try {
    store_.release_lease(vehicle, id_);
  } catch (const std::exception& e) {  // it lapses at its expiry instead
    spdlog::error("vehicle {}: lease not released: {}", input::printable(vehicle), e.what());
  }
  releasing_.erase(vehicle);
}

void LeaseKeeper::release_all() {
  stop();
  std::vector<std::string> vehicles;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [vehicle, until] : held_) vehicles.push_back(vehicle);
    held_.clear();
  }
  for (const auto& vehicle : vehicles) release(vehicle);
  release(heartbeat_name(id_));
  spdlog::info("{}: {} leases released", input::printable(id_), vehicles.size());
}

// Read now, not the renewal's copy: a server that joined since shows at once.
std::vector<store::Lease> LeaseKeeper::leases() {
  std::lock_guard lock(mutex_);
  const std::int64_t database_now =
      database_now_ns_ + std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - database_now_at_).count();
  std::vector<store::Lease> live;
  for (const auto& lease : store_.leases())
    if (lease.expires_ns > database_now) live.push_back(lease);
  return live;
}

}  // namespace dynid::server
