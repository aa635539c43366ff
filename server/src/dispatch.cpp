// Server::Impl: the dispatcher's steps, from DDS samples to worker tasks (server.hpp).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>

#include <dynid/input/ids.hpp>

#include "dynid/dds/conversions.hpp"
#include "server_impl.hpp"

namespace dynid::server {

namespace {

constexpr std::size_t kTakePerRound = 64;
constexpr std::size_t kMaxUnservedAnnouncements = 4096;

// An id field of a sample that failed from_wire, if it is still a terminated string.
std::optional<std::string> readable_id(const char (&field)[sizeof(dynid_wire_Id)]) {
  const std::size_t length = strnlen(field, sizeof field);
  if (length == 0 || length == sizeof field) return std::nullopt;
  return std::string(field, length);
}

dds::Reply reply_to(const dds::Request& request, dds::ReplyStatus status, std::string error) {
  return {request.client, request.correlation_id, status, std::move(error), "text/plain", {}};
}

// The requests that compute over a whole stored run (seconds to minutes on a long one): their
// start and end are logged with the time taken, so that an operator sees what a worker is doing.
bool computes(const std::string& kind) {
  for (const char* k :
       {"residual", "add-effect", "trace", "consistency", "iv", "simex", "reprocess", "export"})
    if (kind == k) return true;
  return false;
}

dds::Reply timed(const dds::Request& request, const std::function<dds::Reply()>& work) {
  if (!computes(request.kind)) return work();
  const auto start = std::chrono::steady_clock::now();
  spdlog::info("request {}#{}: {} started", input::printable(request.client),
               request.correlation_id, request.kind);
  dds::Reply reply = work();
  spdlog::info("request {}#{}: {} finished in {:.1f} s", input::printable(request.client),
               request.correlation_id, request.kind,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return reply;
}

}  // namespace

std::shared_ptr<Cancellation> InFlight::begin(const ReplyCache::Key& key,
                                              dds_instance_handle_t writer) {
  auto cancellation = std::make_shared<Cancellation>();
  std::lock_guard lock(mutex_);
  if (stopping_) cancellation->cancel("the server is stopping");
  running_.insert_or_assign(key, Entry{cancellation, writer});
  return cancellation;
}

void InFlight::end(const ReplyCache::Key& key) {
  std::lock_guard lock(mutex_);
  running_.erase(key);
}

void InFlight::cancel_gone(const std::function<bool(dds_instance_handle_t)>& present) {
  std::lock_guard lock(mutex_);
  for (auto& [key, entry] : running_)
    if (entry.writer != 0 && !entry.cancellation->cancelled() && !present(entry.writer)) {
      spdlog::info("request {}#{}: its client has gone; cancelled", input::printable(key.first),
                   key.second);
      entry.cancellation->cancel("the client that asked has gone");
    }
}

void InFlight::stop() {
  std::lock_guard lock(mutex_);
  stopping_ = true;
  for (auto& [key, entry] : running_) entry.cancellation->cancel("the server is stopping");
}

bool Server::Impl::serves(const std::string& vehicle) {
  if (!leases) return options.shard.owns(vehicle);
  switch (leases->serves(vehicle)) {
    case LeaseKeeper::Serves::held:
      return true;
    case LeaseKeeper::Serves::taken: {  // another server may have served it meanwhile
      const std::size_t worker = pool.worker_of(vehicle);
      pool.post(worker, [this, worker, vehicle] { services[worker]->take_over(vehicle); });
      announce_unserved(vehicle, worker);
      return true;
    }
    case LeaseKeeper::Serves::other:
      break;
  }
  return false;
}

void Server::Impl::keep_unserved(ingest::RunAnnouncement announcement) {
  if (unserved_announcements.size() >= kMaxUnservedAnnouncements)
    unserved_announcements.erase(unserved_announcements.begin());  // bounded: one goes
  store::RunKey key{announcement.vehicle, announcement.run};
  unserved_announcements.insert_or_assign(std::move(key), std::move(announcement));
}

// add_run is idempotent: an announcement its holder recorded already is `already_known`.
void Server::Impl::announce_unserved(const std::string& vehicle, std::size_t worker) {
  auto it = unserved_announcements.lower_bound({vehicle, {}});
  while (it != unserved_announcements.end() && it->first.vehicle == vehicle) {
    pool.post(worker, [this, worker, a = std::move(it->second)] { services[worker]->announce(a); });
    it = unserved_announcements.erase(it);
  }
}

void Server::Impl::dispatch_round() {
  dispatch_announcements();  // first: a run's announcement before its chunks
  dispatch_chunks();
  dispatch_requests();
  in_flight.cancel_gone([this](dds_instance_handle_t writer) { return requests.matches(writer); });
}

void Server::Impl::dispatch_announcements() {
  for (auto& sample : announcements.take(kTakePerRound)) {
    ingest::RunAnnouncement announcement;
    try {
      announcement = dds::from_wire(sample.data);
    } catch (const InputError& e) {
      counters.add(&CounterSnapshot::rejected_announcements);
      spdlog::warn("announcement rejected: {}", e.what());
      continue;
    }
    if (!serves(announcement.vehicle)) {
      counters.add(&CounterSnapshot::not_owned);
      if (leases) keep_unserved(std::move(announcement));
      continue;
    }
    const std::size_t worker = pool.worker_of(announcement.vehicle);
    pool.post(worker, [this, worker, a = std::move(announcement)] { services[worker]->announce(a); });
  }
}

void Server::Impl::dispatch_chunks() {
  for (auto& sample : chunks.take(kTakePerRound)) dispatch_chunk(sample.data);
}

void Server::Impl::dispatch_chunk(const dynid_wire_Chunk& sample) {
  std::shared_ptr<ingest::Chunk> chunk;
  std::string error;
  try {
    chunk = std::make_shared<ingest::Chunk>(dds::from_wire(sample));
  } catch (const InputError& e) {
    error = e.what();
  }
  const auto vehicle = chunk ? std::optional(chunk->vehicle) : readable_id(sample.vehicle);
  const auto run = chunk ? std::optional(chunk->run) : readable_id(sample.run);
  if (vehicle && !serves(*vehicle)) {
    counters.add(&CounterSnapshot::not_owned);
    return;
  }
  if (!vehicle || !run) {  // nobody to tell: count and log only
    counters.add(&CounterSnapshot::chunks_rejected);
    spdlog::warn("chunk rejected (sender unknown): {}", error);
    return;
  }
  const std::size_t worker = pool.worker_of(*vehicle);
  RunService* service = services[worker].get();
  if (chunk) {
    pool.post(worker, [service, chunk = std::move(chunk)] { service->receive_chunk(chunk); });
  } else {
    pool.post(worker, [service, v = *vehicle, r = *run, s = sample.sequence_number, error] {
      service->reject_unreadable(v, r, s, error);
    });
  }
}

void Server::Impl::dispatch_requests() {
  for (auto& sample : requests.take(kTakePerRound)) {
    counters.add(&CounterSnapshot::requests);
    try {
      accept_request(dds::from_wire(sample.data), sample.publication_handle);
    } catch (const InputError& e) {
      counters.add(&CounterSnapshot::requests_rejected);
      spdlog::warn("request rejected: {}", e.what());
      if (const auto client = readable_id(sample.data.client))
        send({*client, sample.data.correlation_id, dds::ReplyStatus::kBadRequest, e.what(),
              "text/plain", {}});
    }
  }
}

// Every server sees every request (docs/DESIGN.md, Scale-out). One naming a vehicle is its
// server's (its shard's, or its lease holder's); a fleet is answered by the owners of its
// vehicles (one computes it, or each refuses a fleet that spans shards; with leases every
// server is shard 0/1 and computes it from the shared store); the others (vehicles, status) by
// every server, the client merges.
bool Server::Impl::concerns_this_shard(const ParsedRequest& parsed) {
  if (const auto vehicle = parsed.optional("vehicle")) return serves(*vehicle);
  if (parsed.kind != "fleet") return true;
  const auto vehicles = split_list(parsed.required("vehicles"));
  return vehicles.empty() ||
         std::any_of(vehicles.begin(), vehicles.end(), [&](const auto& v) { return options.shard.owns(v); });
}

// Parses, routes to a shard and a worker, executes there and replies.
void Server::Impl::accept_request(const dds::Request& request, dds_instance_handle_t writer) {
  ParsedRequest parsed;
  try {
    parsed = parse_request(request);
  } catch (const InputError& e) {
    counters.add(&CounterSnapshot::requests_rejected);
    spdlog::warn("{}", e.what());
    return send(reply_to(request, dds::ReplyStatus::kBadRequest, e.what()));
  }
  if (!concerns_this_shard(parsed)) return;  // another shard's to answer
  const auto vehicle = parsed.optional("vehicle");
  const ReplyCache::Key key{request.client, request.correlation_id};
  std::optional<dds::Reply> cached;
  if (!reply_cache.begin(key, cached)) {
    if (cached) send(*cached);  // the client did not hear the first one
    return;
  }
  if (parsed.kind == "fleet") return dispatch_fleet(parsed, request, key);
  const std::size_t worker = vehicle ? pool.worker_of(*vehicle) : 0;
  // Registered before it is queued: a client that leaves while its request waits is seen too.
  std::shared_ptr<const Cancellation> cancellation = in_flight.begin(key, writer);
  // A close is never cancelled: it changes the run, and must end as it began.
  pool.post(worker, [this, worker, parsed, request, key, cancellation] {
    const CancellationScope scope(parsed.kind == "close" ? nullptr : cancellation);
    answer(request, key, [&] {
      cancellation_point();  // not started for a client that has gone
      return timed(request, [&] { return execute(parsed, *services[worker]); });
    });
    in_flight.end(key);
  });
}

void Server::Impl::answer(const dds::Request& request, const ReplyCache::Key& key,
                          const std::function<dds::Reply()>& work) {
  dds::Reply reply;
  try {
    reply = work();
  } catch (const Cancelled& e) {  // nobody waits for it: the reply is for the log and the cache
    counters.add(&CounterSnapshot::requests_cancelled);
    spdlog::info("request {}#{} {}: {}", input::printable(request.client), request.correlation_id,
                 request.kind, e.what());
    reply = reply_to(request, dds::ReplyStatus::kFailed, e.what());
  } catch (const NotFound& e) {
    counters.add(&CounterSnapshot::requests_rejected);
    reply = reply_to(request, dds::ReplyStatus::kNotFound, e.what());
  } catch (const InputError& e) {
    counters.add(&CounterSnapshot::requests_rejected);
    reply = reply_to(request, dds::ReplyStatus::kBadRequest, e.what());
  } catch (const std::exception& e) {
    spdlog::error("request {}#{} failed: {}", input::printable(request.client), request.correlation_id, e.what());
    reply = reply_to(request, dds::ReplyStatus::kFailed, e.what());
  }
  reply.client = request.client;
  reply.correlation_id = request.correlation_id;
  reply_cache.finish(key, reply);
  send(reply);
}

}  // namespace dynid::server
