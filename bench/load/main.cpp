// dynid-load: the load benchmark's vehicles (load_fleet.hpp). Prints one JSON line with the
// figures (LoadResult::to_json) after a short human summary on stderr (resends and the ack
// latency's definition included); exits 0 when no chunk
// was lost, every vehicle was acknowledged to its last chunk and has an estimate with the
// expected row count, and no chunk was rejected; 1 otherwise; 2 on a bad command line.
#include <CLI/CLI.hpp>
#include <cmath>
#include <iostream>

#include "dynid/dds/participant.hpp"
#include "load_fleet.hpp"

int main(int argc, char** argv) {
  dynid::load::LoadOptions o;
  std::string config;
  std::vector<std::string> fragments;
  long long rss_ms = 0, patience_s = 60, drain_s = 60;
  double ack_timeout_s = 5.0;
  bool fast = false;
  CLI::App app{
      "dynid-load: N simulated vehicles streaming the body model's 30 channels into "
      "the dynid-server(s) of a domain over DDS; measures acks, estimates, latency, resends, "
      "server CPU/RSS"};
  app.add_option("--cyclone-config", config, "Cyclone configuration file (loopback.xml)")
      ->required();
  app.add_option("--cyclone-fragment", fragments, "XML fragment appended (e.g. a discovery tag)");
  app.add_option("--domain", o.domain, "DDS domain id")->check(CLI::Range(0, 230));
  app.add_option("--vehicles", o.vehicles, "simulated vehicles")->check(CLI::PositiveNumber);
  app.add_option("--chunks", o.chunks_per_vehicle, "chunks per vehicle")
      ->check(CLI::PositiveNumber);
  app.add_option("--chunk-rows", o.chunk_rows, "samples per chunk")->check(CLI::Range(1L, 100000L));
  app.add_option("--rate", o.sample_rate_hz, "sample rate per vehicle, Hz")
      ->check(CLI::PositiveNumber);
  app.add_option("--odmf", o.odmf, "announced decimation factor")->check(CLI::Range(1, 1000));
  app.add_flag("--fast", fast, "as fast as the window allows instead of real time");
  app.add_option("--window", o.window, "fast mode: unacknowledged chunks per vehicle")
      ->check(CLI::PositiveNumber);
  app.add_option("--server-pid", o.server_pids,
                 "read a server's CPU and memory from /proc (repeat: summed over the servers)");
  app.add_option("--servers", o.servers, "servers (chunk readers) to discover before starting")
      ->check(CLI::Range(1, 64));
  app.add_option("--ack-timeout", ack_timeout_s,
                 "seconds without acknowledgement before resending what is in flight (as "
                 "dynid-car's --ack-timeout)")
      ->check(CLI::Range(0.01, 3600.0));
  app.add_option("--rss-period-ms", rss_ms, "sample the server's RSS this often (soak)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--patience", patience_s, "seconds for discovery and announcements")
      ->check(CLI::PositiveNumber);
  app.add_option("--drain", drain_s, "seconds to wait for acks and estimates after the last write")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--prefix", o.prefix, "vehicle ids <prefix>-<k>");
  CLI11_PARSE(app, argc, argv);
  o.paced = !fast;
  o.rss_period = std::chrono::milliseconds(rss_ms);
  o.patience = std::chrono::seconds(patience_s);
  o.drain = std::chrono::seconds(drain_s);
  o.ack_timeout = std::chrono::milliseconds(std::llround(ack_timeout_s * 1000.0));
  try {
    o.cyclone_config = dynid::dds::config_file_uri(config);
    for (const auto& f : fragments) o.cyclone_config += "," + f;
    const auto r = dynid::load::run_load(o);
    std::cerr << "dynid-load: " << r.vehicles << " vehicles, " << r.chunks_acked << "/"
              << r.chunks_written << " chunks acked in " << r.stream_seconds << " s ("
              << static_cast<double>(r.sample_rows_acked) / r.stream_seconds << " rows/s), lost "
              << r.lost << ", missed " << r.missed << ", rejections " << r.rejections
              << "; ack latency (first send of a chunk -> its acknowledgement) p50 " << r.ack_p50_ms
              << " ms p99 " << r.ack_p99_ms << " ms; estimate latency p50 " << r.estimate_p50_ms
              << " ms p99 " << r.estimate_p99_ms << " ms; resent " << r.resent_chunks
              << " chunks in " << r.resend_rounds << " rounds (ack timeout " << r.ack_timeout_ms
              << " ms)\n";
    std::cout << r.to_json() << std::endl;
    const bool ok = r.lost == 0 && r.missed == 0 && r.rejections == 0 && r.final_rows_wrong == 0 &&
                    r.vehicles_fully_acked == r.vehicles && r.vehicles_with_estimate == r.vehicles;
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "dynid-load: " << e.what() << "\n";
    return 1;
  }
}
