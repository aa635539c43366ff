#pragma once
// ServerOptions: everything dynid-server is started with, and their command-line form (CLI11).
//
//   --store PATH             SQLite store (created if absent; an existing path
//                            must be a regular file)                          required
//   --cyclone-config CONFIG  Cyclone configuration: a file path, a file:// URI or an XML
//                            fragment list as in CYCLONEDDS_URI. Required: the server never
//                            runs on Cyclone's default configuration (it picks the machine's
//                            default interface).
//   --domain D               DDS domain id, 0..230 (0)
//   --threads T              folding workers, 0..kMaxThreads (0: one per core)
//   --checkpoint-every N     save a run's accumulators every N folded chunks,
//                            1..kMaxCheckpointEvery (50)
//   --publish-interval-ms M  publish a run's estimates at most every M ms,
//                            0..kMaxPublishIntervalMs (250)
//   --live-residual S        keep the residual loop's verdict of every open run current, at
//                            most every S seconds of a run's growth (and at its close), and
//                            publish it beside the estimates; 0..kMaxLiveResidualS (0: off).
//                            The diagnosis replays the stored run on the run's worker: it costs
//                            that worker about a second per model and run (docs/RESIDUAL.md)
//   --shard K/N              own the vehicles whose hash mod N == K (0/1: all). SQLite only:
//                            with a PostgreSQL store, leases decide (lease_keeper.hpp)
//   --server-id ID           this server's holder id in the leases of a PostgreSQL store
//                            (default <hostname>-<pid>); printed at start
//   --lease-ttl S            how long a lease lasts unrenewed, in seconds, 0.3..3600 (3); renewed
//                            every third of it. A dead server's vehicles move after about this
//   --reorder-window W       chunks stored ahead of a gap (store.hpp), 1..kMaxReorderWindow (256)
//   --log-level L            trace, debug, info, warn, error (info)
//
// parse_options() throws InputError with CLI11's message on a bad command line (a number
// outside its limits, NaN or not a number included; --shard other than 0/1 with a PostgreSQL
// store; a --server-id that is not an id, input/ids.hpp), and returns std::nullopt after
// printing --help.
#include <dds/dds.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "dynid/server/shard.hpp"
#include "dynid/store/store.hpp"

namespace dynid::server {

// Limits of the numeric options: far above any use, below what breaks (threads a process can
// start, a duration's count).
inline constexpr unsigned kMaxThreads = 256;
inline constexpr std::uint64_t kMaxCheckpointEvery = 1000000;
inline constexpr long long kMaxPublishIntervalMs = 3600000;
inline constexpr std::uint64_t kMaxReorderWindow = 1000000;
inline constexpr long long kMaxLiveResidualS = 86400;
inline constexpr double kMinLeaseTtlS = 0.3;
inline constexpr double kMaxLeaseTtlS = 3600;

struct ServerOptions {
  std::string store_path;  ///< --store: an SQLite file or a postgresql:// URI (store/location.hpp)
  std::string cyclone_config;  ///< as given; see cyclone_config_uri()
  dds_domainid_t domain = 0;
  unsigned threads = 0;
  std::uint64_t checkpoint_every = 50;
  std::chrono::milliseconds publish_interval{250};
  std::chrono::seconds live_residual_interval{0};  ///< 0: the live verdict is off
  Shard shard;
  std::string server_id;  ///< set by parse_options (a default when not given)
  std::chrono::milliseconds lease_ttl{3000};
  store::StoreOptions store;
  std::string log_level = "info";

  /// The worker count actually used (threads, or the number of cores, at least 1).
  unsigned worker_count() const;
  /// Whether the store is shared by several servers (a PostgreSQL location): then vehicles are
  /// served under leases (lease_keeper.hpp), else by --shard.
  bool leased() const;
};

/// What Participant expects (dds::config_uri). Throws InputError for an empty value or a file
/// that is not a regular file, DdsError for a path that does not exist.
std::string cyclone_config_uri(const std::string& value);

/// <hostname>-<pid>, made to follow the id rule (input/ids.hpp).
std::string default_server_id();

std::optional<ServerOptions> parse_options(int argc, const char* const* argv);

}  // namespace dynid::server
