#pragma once
// Server: dynid-server in one object, so tests can run it in-process as well as through the
// executable (src/main.cpp).
//
// Threads: one dispatcher (run()) waits on a waitset over the RunAnnouncement, Chunk and
// Request readers (all vehicles' partitions, "vehicle/*"), converts each sample (from_wire)
// and posts it to the worker its vehicle is pinned to (WorkerPool), announcements before
// chunks in every round, so a run's announcement is handled before the chunks that follow it.
// Workers store, acknowledge, fold and publish (RunService); requests run on the worker of the
// vehicle they name (fleet-wide ones on worker 0) and are answered on the Reply topic.
// A repeated request (same client and correlation id: the client resends when it hears
// nothing) is answered again from a cache of recent replies, not executed twice.
//
// Contract:
// - The constructor opens the store, joins the domain with options.cyclone_config (required,
//   never Cyclone's default), starts the workers and queues the resumption of every open run
//   of this shard. StoreError/CorruptionError/DdsError/InputError on failure; InputError too
//   when the store holds vehicles another shard owns (shard.hpp).
// - Several servers on SQLite stores (options.shard K/N): samples of vehicles of other shards
//   are dropped; requests naming a vehicle are answered by its owner only, vehicles/status by
//   every shard, and every reply carries the shard (docs/DESIGN.md, "Scale-out").
// - Several servers on one PostgreSQL store (options.leased()): a vehicle is served by the
//   holder of its lease (lease_keeper.hpp); the store is fenced by options.server_id, so a
//   server writes nothing of a vehicle it does not hold. Samples and requests of a vehicle held
//   elsewhere are dropped (the holder answers); one whose lease is free is taken when the fair
//   share allows, and its runs are loaded from the store (checkpoint + the chunks after it)
//   before anything new is folded. No run is resumed at start: a vehicle's runs are loaded
//   when its lease is taken. Requests naming no vehicle are answered by every server, as shard
//   0/1 (the client keeps the first: the store is the same). Stopping (the destructor) releases
//   every lease after the last acknowledged write.
// - run() dispatches until stop(); stop() may be called from any thread (not from a signal
//   handler: main.cpp waits for signals with sigwait). After run() returns, the destructor
//   lets the workers finish what is queued.
// - Bad input never ends the server: a malformed sample or request is rejected, counted
//   (counters()), logged, and changes no state.
#include <memory>

#include "dynid/server/counters.hpp"
#include "dynid/server/options.hpp"

namespace dynid::server {

class Server {
 public:
  explicit Server(ServerOptions options);
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;
  ~Server();

  void run();
  void stop();
  CounterSnapshot counters() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynid::server
