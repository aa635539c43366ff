// dynid-car: the car-side client. Reads the CAN bus (SocketCAN) or replays a candump log,
// decodes it with the vehicle profile, cuts chunks, keeps them in the spool and delivers them to
// the server until it acknowledges them durably (delivery.hpp).
//
//   dynid-car --profile deploy/profiles/testcar.toml --cyclone-config deploy/cyclonedds/loopback.xml
//             --replay can.log --fast [--run ID] [--spool DIR]
//   dynid-car --profile P --cyclone-config C --can can0
//   dynid-car --profile P --cyclone-config C          # only deliver what the spool still holds
//
// Exit status: 0 everything acknowledged; 1 bad arguments or input, or a failure; 2 chunks left
// unacknowledged after --drain-timeout (they stay in the spool for the next start); 3 the spool
// filled up and reading stopped (also with chunks left); 130 interrupted.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <ctime>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <dynid/dds/participant.hpp>
#include <dynid/error.hpp>

#include "dynid/car/candump_source.hpp"
#include "dynid/car/delivery.hpp"
#include "dynid/car/pipeline.hpp"
#include "dynid/car/progress_display.hpp"
#include "dynid/car/replay.hpp"
#include "dynid/car/socketcan_source.hpp"
#include "dynid/car/spool.hpp"
#include "dynid/car/uplink.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace {

using namespace dynid::car;
using namespace std::chrono_literals;

struct Options {
  std::string profile;
  std::string run;
  std::string cyclone_config;
  int domain = 0;
  std::string replay;
  std::string can;
  double speed = 1.0;
  bool fast = false;
  std::string spool;
  double drain_timeout = 60.0;
  double ack_timeout = 5.0;
};

constexpr const char* kLogPattern = "dynid-car %l: %v";

enum Exit { kOk = 0, kFailed = 1, kUndelivered = 2, kSpoolFull = 3, kInterrupted = 130 };

// Signals: stop reading (the live source wakes at once), then drain as usual. A second signal
// ends the process the default way.
std::atomic<bool> g_stop{false};
std::atomic<SocketCanSource*> g_live{nullptr};
extern "C" void on_signal(int sig) {
  if (g_stop.exchange(true)) {
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  if (SocketCanSource* live = g_live.load()) live->request_stop();
}

struct Interrupted {};

std::string default_run_id() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "run-%Y%m%dT%H%M%SZ", &tm);
  return buf;
}

// As dynid-server takes it: "file://..." or "<..." (comma-separated, as in CYCLONEDDS_URI) is
// used as it is, e.g. a file plus a discovery tag; anything else is a path to a file.
std::string cyclone_uri(const std::string& value) {
  if (value.rfind("file://", 0) == 0 || value.rfind('<', 0) == 0) return value;
  return dynid::dds::config_file_uri(value);
}

// A run id names one recording: reusing one would mix two runs' chunks under one sequence.
void check_new_run(const Spool& spool, const std::string& vehicle, const std::string& run) {
  bool known = spool.acknowledged(vehicle, run).has_value();
  for (const auto& e : spool.pending_entries()) known = known || (e.vehicle == vehicle && e.run == run);
  if (known)
    throw dynid::InputError("run " + vehicle + "/" + run + " is already in the spool " + spool.file().string() +
                            " (its unacknowledged chunks are resent automatically): choose a new --run");
}

struct Session {
  const Options& options;
  const VehicleProfile& profile;
  Spool& spool;
  Delivery& delivery;
  ProgressDisplay& display;
  bool spool_full = false;
  std::string source_name = "resending the spool";
  ReplayProgress last = [] {  // of the source, shown again while draining
    ReplayProgress none;
    none.fraction = -1.0;
    return none;
  }();

  void show(const ReplayProgress& p, bool force = false) {
    last = p;
    display.update(format_progress(source_name, p, delivery.stats(), delivery.pending(), spool.bytes()), force);
  }

  // The sink of the pipeline: spool, then send. SpoolFull propagates and stops the reading.
  CarPipeline pipeline(const std::string& run) {
    return CarPipeline(profile, run, [this](dynid::ingest::Chunk&& chunk) {
      delivery.submit(chunk);
      if (g_stop.load()) throw Interrupted{};
    });
  }

  void replay_log(const std::string& run) {
    CandumpSource source(options.replay);
    CarPipeline pipe = pipeline(run);
    ReplayOptions ro;
    ro.speed = options.fast ? 0.0 : options.speed;
    ro.progress_interval = 100ms;  // also how often acknowledgements are taken while replaying
    source_name = std::filesystem::path(options.replay).filename().string();
    ro.on_progress = [&](const ReplayProgress& p) {
      delivery.service(0ms);
      show(p, p.done);
      if (g_stop.load()) throw Interrupted{};
    };
    const ReplayProgress done = replay(source, pipe, ro);
    spdlog::info("replay done: {} frames ({} bad lines, {} unknown ids), {:.1f} s of log, {} chunks", done.frames,
                 source.bad_input(), done.unknown_id, done.log_seconds, done.chunks);
    for (const auto& e : source.errors()) spdlog::warn("{}", e);
  }

  void read_bus(const std::string& run) {
    SocketCanSource source(options.can);
    g_live.store(&source);
    struct Unregister {
      ~Unregister() { g_live.store(nullptr); }
    } unregister;
    CarPipeline pipe = pipeline(run);
    source_name = "live " + options.can;
    dynid::can::Frame frame;
    auto next_service = std::chrono::steady_clock::now();
    for (;;) {
      const NextStatus status = source.next(frame, 100ms);
      if (status == NextStatus::End) break;
      if (status == NextStatus::Frame) pipe.on_frame(frame);
      // No frame: the grid clock still moves (receive times are CLOCK_REALTIME), so rows leave.
      if (status == NextStatus::Timeout)
        pipe.idle(std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count());
      if (std::chrono::steady_clock::now() >= next_service) {
        delivery.service(0ms);
        ReplayProgress p;
        p.frames = pipe.mapper_stats().frames;
        p.fraction = -1.0;
        show(p);
        next_service = std::chrono::steady_clock::now() + 100ms;
      }
    }
    pipe.finish();
    spdlog::info("bus {} closed: {} frames, {} error frames, {} dropped by the kernel, {} chunks", options.can,
                 source.frames(), source.error_frames(), source.dropped(), pipe.chunks());
  }

  void read_source() {
    const std::string run = options.run.empty() ? default_run_id() : options.run;
    check_new_run(spool, profile.vehicle, run);
    delivery.announce(profile.announcement(run));
    spdlog::info("run {}/{}: {} channels at {} Hz, {} rows per chunk", profile.vehicle, run, profile.channels.size(),
                 profile.rate_hz, profile.chunk_rows);
    // A replay can wait a moment until the server has taken the announcement (it answers with a
    // receipt), so the first chunks neither go into the void nor overtake the announcement
    // (both would be resent anyway); a live bus cannot wait.
    if (!options.replay.empty() && !wait_for_server(run, 3s))
      spdlog::warn("no server took the announcement within 3 s: spooling, and sending when one appears");
    try {
      if (!options.replay.empty()) replay_log(run);
      else read_bus(run);
    } catch (const SpoolFull& e) {
      // Stop reading rather than drop anything: what is stored is still delivered below.
      spool_full = true;
      display.finish();
      spdlog::error("{}; stopped reading {} — the rest of the run is not recorded",
                    e.what(), options.replay.empty() ? options.can : options.replay);
    } catch (const Interrupted&) {
      display.finish();
      spdlog::warn("interrupted: stopped reading; delivering what is stored");
    }
  }

  bool wait_for_server(const std::string& run, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!delivery.server_knows(profile.vehicle, run) && std::chrono::steady_clock::now() < deadline)
      delivery.service(50ms);
    return delivery.server_knows(profile.vehicle, run);
  }

  bool drain() {
    const auto timeout = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::duration<double>(options.drain_timeout));
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    const ReplayProgress source_done = last;
    while (!delivery.drained() && std::chrono::steady_clock::now() < deadline) {
      delivery.drain(std::min(timeout, std::chrono::milliseconds(200)));
      show(source_done);
    }
    show(source_done, true);
    display.finish();
    return delivery.drained();
  }
};

int run(const Options& options, ProgressDisplay& display) {
  const VehicleProfile profile = load_vehicle_profile(options.profile);
  const std::filesystem::path spool_dir = options.spool.empty() ? profile.spool_directory : std::filesystem::path(options.spool);
  Spool spool(spool_dir, profile.spool_max_bytes);
  spdlog::info("vehicle {}: spool {} ({} chunks pending)", profile.vehicle, spool.file().string(), spool.count());

  dynid::dds::Participant participant({static_cast<dds_domainid_t>(options.domain), cyclone_uri(options.cyclone_config)});
  Uplink uplink(participant, profile.vehicle);
  DeliveryOptions delivery_options;
  delivery_options.ack_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(options.ack_timeout));
  Delivery delivery(spool, uplink, delivery_options, [](LogLevel level, const std::string& message) {
    spdlog::log(level == LogLevel::info ? spdlog::level::info
                : level == LogLevel::warning ? spdlog::level::warn : spdlog::level::err, "{}", message);
  });


  Session session{options, profile, spool, delivery, display};
  if (!options.replay.empty() || !options.can.empty()) session.read_source();
  const bool drained = session.drain();
  const auto& s = delivery.stats();
  if (uplink.bad_receipts() > 0)
    spdlog::warn("{} malformed acknowledgements ignored, last: {}", uplink.bad_receipts(), uplink.last_bad_receipt());
  if (!drained) {
    spdlog::error("not everything was acknowledged within {} s: {}; it stays in {} and is resent on the next start",
                  options.drain_timeout, delivery.holdup(), spool.file().string());
    return session.spool_full ? kSpoolFull : kUndelivered;
  }
  spdlog::info("all chunks acknowledged: {} stored, {} sent, {} resent in {} rounds, {} rejections", s.submitted,
               s.sent, s.resent, s.resend_rounds, s.rejections);
  if (session.spool_full) return kSpoolFull;
  return g_stop.load() ? kInterrupted : kOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynid-car: reads the CAN bus or replays a log and delivers the run's chunks to dynid-server"};
  Options o;
  app.add_option("--profile", o.profile, "vehicle profile (TOML)")->required()->check(CLI::ExistingFile);
  app.add_option("--run", o.run, "run id (default: run-<UTC time>)");
  app.add_option("--cyclone-config", o.cyclone_config,
                 "Cyclone DDS configuration: a file (deploy/cyclonedds/*.xml), or file:// URIs and XML "
                 "fragments, comma-separated, as in CYCLONEDDS_URI")
      ->required();
  app.add_option("--domain", o.domain, "DDS domain id")->check(CLI::Range(0, 230));
  auto* replay_opt = app.add_option("--replay", o.replay, "replay this candump -l log")->check(CLI::ExistingFile);
  auto* can_opt = app.add_option("--can", o.can, "read this SocketCAN interface live (e.g. can0)");
  replay_opt->excludes(can_opt);
  auto* speed_opt = app.add_option("--speed", o.speed, "replay speed (1 = real time)")
                        ->check(CLI::PositiveNumber)->needs(replay_opt);
  app.add_flag("--fast", o.fast, "replay as fast as possible")->needs(replay_opt)->excludes(speed_opt);
  app.add_option("--spool", o.spool, "spool folder (default: the profile's [spool] directory)");
  app.add_option("--drain-timeout", o.drain_timeout, "seconds to wait for the last acknowledgements")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--ack-timeout", o.ack_timeout, "seconds without acknowledgement before resending")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  // Everything on stderr, through the display so log lines never tear the progress line.
  ProgressDisplay display(stderr, isatty(STDERR_FILENO) != 0);
  spdlog::default_logger()->sinks().clear();
  spdlog::default_logger()->sinks().push_back(display.log_sink());
  spdlog::set_pattern(kLogPattern);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    return run(o, display);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kFailed;
  }
}
