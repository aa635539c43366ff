#include "dynid/server/options.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <thread>

#include "dynid/dds/participant.hpp"
#include "dynid/error.hpp"

namespace dynid::server {

unsigned ServerOptions::worker_count() const {
  if (threads > 0) return threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

std::string cyclone_config_uri(const std::string& value) {
  if (value.empty()) throw InputError("--cyclone-config: empty (a configuration is required)");
  if (value.rfind("file://", 0) == 0 || value.front() == '<') return value;
  return dds::config_file_uri(value);
}

std::optional<ServerOptions> parse_options(int argc, const char* const* argv) {
  ServerOptions o;
  std::string shard = "0/1";
  long long publish_ms = o.publish_interval.count();
  CLI::App app{"dynid-server: archives measurement chunks, identifies parameters, publishes "
               "estimates over Cyclone DDS"};
  app.add_option("--store", o.store_path, "SQLite store file")->required();
  app.add_option("--cyclone-config", o.cyclone_config,
                 "Cyclone DDS configuration (file, file:// URI or XML)")
      ->required();
  app.add_option("--domain", o.domain, "DDS domain id")->check(CLI::Range(0, 230));
  app.add_option("--threads", o.threads, "folding workers (0: one per core)");
  app.add_option("--checkpoint-every", o.checkpoint_every, "checkpoint every N folded chunks")
      ->check(CLI::PositiveNumber);
  app.add_option("--publish-interval-ms", publish_ms, "minimum time between estimate updates")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--shard", shard, "own the vehicles whose hash mod N == K (K/N)");
  app.add_option("--reorder-window", o.store.reorder_window, "chunks stored ahead of a gap")
      ->check(CLI::PositiveNumber);
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
  o.publish_interval = std::chrono::milliseconds(publish_ms);
  return o;
}

}  // namespace dynid::server
