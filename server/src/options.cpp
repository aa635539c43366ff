#include "dynid/server/options.hpp"

#include <CLI/CLI.hpp>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <thread>

#include "dynid/dds/participant.hpp"
#include "dynid/error.hpp"
#include "dynid/input/ids.hpp"
#include "dynid/options/option_checks.hpp"
#include "dynid/store/location.hpp"

namespace dynid::server {

unsigned ServerOptions::worker_count() const {
  if (threads > 0) return threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

bool ServerOptions::leased() const { return store::is_postgres_uri(store_path); }

std::string cyclone_config_uri(const std::string& value) {
  if (value.empty()) throw InputError("--cyclone-config: empty (a configuration is required)");
  return dds::config_uri(value);
}

namespace {

// The store is created if absent; an existing path must be a regular file (SQLite on a FIFO
// or a device would block or fail obscurely). A postgresql:// URI names a database instead.
CLI::Validator new_or_regular_file() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        if (store::is_postgres_uri(path)) return {};  // a database, not a file
        std::error_code ec;
        if (!std::filesystem::exists(std::filesystem::symlink_status(path, ec))) return {};
        try {
          input::check_input_file(path, "store");
        } catch (const InputError& e) {
          return e.what();
        }
        return {};
      },
      "FILE");
}

}  // namespace

// Unique among the servers of one database as long as no two run on one machine with one pid
// (an id follows the vehicle-id rule: no ':' in it).
std::string default_server_id() {
  char host[256] = {};
  std::string name = gethostname(host, sizeof host - 1) == 0 ? host : "server";
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '_') c = '-';
  if (name.empty() || !std::isalnum(static_cast<unsigned char>(name.front()))) name = "server" + name;
  return name.substr(0, input::kMaxIdLength - 12) + "-" + std::to_string(getpid());
}

std::optional<ServerOptions> parse_options(int argc, const char* const* argv) {
  ServerOptions o;
  std::string shard = "0/1";
  long long publish_ms = o.publish_interval.count();
  CLI::App app{"dynid-server: archives measurement chunks, identifies parameters, publishes "
               "estimates over Cyclone DDS"};
  app.add_option("--store", o.store_path, "SQLite store file, or a postgresql:// URI")->required()->check(new_or_regular_file());
  app.add_option("--cyclone-config", o.cyclone_config,
                 "Cyclone DDS configuration (file, file:// URI or XML; or $DYNID_CYCLONE_CONFIG)")
      ->envname("DYNID_CYCLONE_CONFIG")
      ->required();
  app.add_option("--domain", o.domain, "DDS domain id")->check(CLI::Range(0, 230));
  app.add_option("--threads", o.threads, "folding workers (0: one per core)")
      ->check(input::within(0, kMaxThreads));
  app.add_option("--checkpoint-every", o.checkpoint_every, "checkpoint every N folded chunks")
      ->check(input::within(1, kMaxCheckpointEvery));
  app.add_option("--publish-interval-ms", publish_ms, "minimum time between estimate updates")
      ->check(input::within(0, kMaxPublishIntervalMs));
  long long live_residual_s = o.live_residual_interval.count();
  app.add_option("--live-residual", live_residual_s,
                 "keep the residual loop's verdict of open runs current, at most every S seconds (0: off)")
      ->check(input::within(0, kMaxLiveResidualS));
  app.add_option("--shard", shard, "own the vehicles whose hash mod N == K (K/N)");
  app.add_option("--server-id", o.server_id, "this server's id in the leases (default <hostname>-<pid>)")
      ->check(input::id("server id"));
  double lease_ttl_s = 3;
  app.add_option("--lease-ttl", lease_ttl_s, "seconds a lease lasts unrenewed (PostgreSQL store)")
      ->check(input::within(kMinLeaseTtlS, kMaxLeaseTtlS));
  app.add_option("--reorder-window", o.store.reorder_window, "chunks stored ahead of a gap")
      ->check(input::within(1, kMaxReorderWindow));
  app.add_option("--log-level", o.log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return std::nullopt;
  } catch (const CLI::ParseError& e) {
    throw InputError(std::string("dynid-server: ") + e.what() + " (see --help)");
  }
  o.shard = Shard::parse(shard);
  if (o.leased() && o.shard.count != 1)
    throw InputError("dynid-server: --shard " + shard + " with a PostgreSQL store: the servers of one "
                     "database share its vehicles by leases, not by --shard (docs/DESIGN.md, Scale-out)");
  if (o.server_id.empty()) o.server_id = default_server_id();
  o.lease_ttl = std::chrono::milliseconds(std::llround(lease_ttl_s * 1000));
  o.publish_interval = std::chrono::milliseconds(publish_ms);
  o.live_residual_interval = std::chrono::seconds(live_residual_s);
  return o;
}

}  // namespace dynid::server
