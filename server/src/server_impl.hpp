#pragma once
// Server::Impl: the members of the server and the dispatcher's steps (server.cpp, dispatch.cpp).
#include <atomic>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>

#include "dynid.h"
#include "dynid/cancellation.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/dds/request.hpp"
#include "dynid/server/lease_keeper.hpp"
#include "dynid/server/request_parser.hpp"
#include "dynid/server/run_service.hpp"
#include "dynid/server/server.hpp"
#include "dynid/server/worker_pool.hpp"

namespace dynid::server {

/// Recent replies by (client, correlation id); nullopt while the request is being executed.
class ReplyCache {
 public:
  using Key = std::pair<std::string, std::uint64_t>;
  /// True when the key is new (and now marked in flight); false with the cached reply, if any.
  bool begin(const Key& key, std::optional<dds::Reply>& cached);
  void finish(const Key& key, const dds::Reply& reply);

 private:
  static constexpr std::size_t kCapacity = 256;
  std::mutex mutex_;
  std::map<Key, std::optional<dds::Reply>> replies_;
  std::deque<Key> order_;
};

/// The requests being executed, each with the Cancellation its computation checks
/// (dynid/cancellation.hpp): cancelled when the server stops, and when the client that sent it
/// has gone (its request writer no longer matched: it exited, or its lease expired), so that
/// nobody's abandoned trace holds a worker.
class InFlight {
 public:
  /// Registers `key`, sent by `writer`; once stop() was called, the cancellation comes cancelled.
  std::shared_ptr<Cancellation> begin(const ReplyCache::Key& key, dds_instance_handle_t writer);
  void end(const ReplyCache::Key& key);
  /// Cancels the requests whose writer `present` no longer finds.
  void cancel_gone(const std::function<bool(dds_instance_handle_t)>& present);
  /// Cancels every request, now and later.
  void stop();

 private:
  struct Entry {
    std::shared_ptr<Cancellation> cancellation;
    dds_instance_handle_t writer = 0;
  };
  std::mutex mutex_;
  std::map<ReplyCache::Key, Entry> running_;
  bool stopping_ = false;
};

struct Server::Impl {
  explicit Impl(ServerOptions options);
  ~Impl();

  /// InputError when the store holds vehicles this shard does not own.
  void refuse_foreign_vehicles();
  /// With a shared store: the lease keeper, and what a lost or given-back lease does.
  void start_leases();
  /// Whether this server serves `vehicle` now: its shard's, or (shared store) its lease's. A
  /// lease just taken first has the vehicle's worker drop what it kept of it (lease_keeper.hpp).
  bool serves(const std::string& vehicle);
  void keep_unserved(ingest::RunAnnouncement announcement);
  /// The announcements kept for `vehicle`, to its worker (a lease just taken).
  void announce_unserved(const std::string& vehicle, std::size_t worker);
  void resume_open_runs();
  void dispatch_round();
  void dispatch_announcements();
  void dispatch_chunks();
  void dispatch_requests();
  void dispatch_chunk(const dynid_wire_Chunk& sample);
  /// Whether this server answers `parsed` (the routing of requests between shards).
  bool concerns_this_shard(const ParsedRequest& parsed);
  /// `writer`: the request's publication handle, watched while the request runs (InFlight).
  void accept_request(const dds::Request& request, dds_instance_handle_t writer);
  dds::Reply execute(const ParsedRequest& request, RunService& service);
  /// Runs `work` and replies with its result, or with the status its exception maps to
  /// (NotFound, InputError, anything else: FAILED); the reply is cached and sent.
  void answer(const dds::Request& request, const ReplyCache::Key& key,
              const std::function<dds::Reply()>& work);
  /// A fleet request: each vehicle's accumulators are read on its own worker, the last one
  /// to be read solves and replies (fleet_request.cpp).
  void dispatch_fleet(const ParsedRequest& request, const dds::Request& raw,
                      const ReplyCache::Key& key);
  std::string fleet_reply(const ParsedRequest& request);
  std::string status_reply();
  /// Writes `reply` stamped with this server's shard.
  void send(dds::Reply reply);

  ServerOptions options;
  ServerCounters counters;
  SharedStore store;
  dds::Participant participant;
  RevisionClock revisions;
  Committer committer{store};  // before the services: stopped after the workers are done
  // Cancelled by stop(): what the workers and the live residual jobs compute ends at its next
  // cancellation point, so that a stop does not wait for a trace.
  std::shared_ptr<Cancellation> stopping_work = std::make_shared<Cancellation>();
  InFlight in_flight;
  ServerContext context{options, store, committer, counters, participant, revisions, stopping_work};
  dds::Reader<dynid_wire_RunAnnouncement> announcements;
  dds::Reader<dynid_wire_Chunk> chunks;
  dds::Reader<dynid_wire_Request> requests;
  dds::Writer<dynid_wire_Reply> replies;
  std::mutex reply_mutex;
  ReplyCache reply_cache;
  std::vector<std::unique_ptr<RunService>> services;  // one per worker
  WorkerPool pool;  // after the services it uses: stopped and destroyed first
  dds::Entity waitset;
  dds::Entity stop_guard;
  std::vector<dds::Entity> conditions;
  std::atomic<bool> stopping{false};
  std::unique_ptr<LeaseKeeper> leases;  // shared store only; after the pool it posts to
  // Announcements of vehicles another server held (shared store; dispatcher thread only): a
  // car announces a run once, so whoever takes the vehicle later must still record it.
  std::map<store::RunKey, ingest::RunAnnouncement> unserved_announcements;
};

}  // namespace dynid::server
