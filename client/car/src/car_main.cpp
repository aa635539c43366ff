// dynid-car: the car-side client. Reads the CAN bus (SocketCAN) or replays CAN logs (candump,
// Vector ASC or BLF, PCAN trace, ASAM MDF4: can/log_reader.hpp; several files, e.g. the splits of
// one recording, are merged in time order: log_source.hpp),
// decodes it with the vehicle profile, cuts chunks, keeps them in the spool and delivers them to
// the server until it acknowledges them durably (delivery.hpp).
//
//   dynid-car --profile deploy/profiles/testcar.toml --cyclone-config
//   deploy/cyclonedds/loopback.xml
//             --replay can.log --fast [--run ID] [--spool DIR]
//   dynid-car --profile P --cyclone-config C --can can0
//   dynid-car --profile P --cyclone-config C          # only deliver what the spool still holds
//   dynid-car --profile P --run R --can can0 --chunks-out run.chunks [--max-frames N]
//   dynid-car --profile P --run R --replay can.log --fast --chunks-out run.chunks
//
// --chunks-out: no server, no DDS, no spool: the sealed chunks go to a file (chunk_file.hpp), cut
// by the same reading code, so a live run can be compared with the replay of a log of the same
// frames (tests/vm). Live timestamps are taken at the microsecond resolution of a candump log
// (read_bus), which is what makes that comparison exact.
//
// A replayed log is judged twice (replay.hpp, replay_problem): its first lines before anything is
// announced, spooled or written (a file that is no usable log changes nothing), and the whole log
// at its end (what it held is delivered, and the exit status is 1).
//
// Exit status: 0 everything acknowledged (or written); 1 bad arguments or input, or a failure; 2
// chunks left unacknowledged after --drain-timeout (they stay in the spool for the next start); 3
// the spool filled up and reading stopped (also with chunks left); 130 interrupted.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <map>
#include <string>
#include <vector>

#include <dynid/can/log_content.hpp>
#include <dynid/dds/participant.hpp>
#include <dynid/error.hpp>
#include <dynid/options/option_checks.hpp>

#include "dynid/car/auxiliary.hpp"
#include "dynid/car/can_interface_follower.hpp"
#include "dynid/car/chunk_file.hpp"
#include "dynid/car/delivery.hpp"
#include "dynid/car/live_merge.hpp"
#include "dynid/car/log_source.hpp"
#include "dynid/car/pipeline.hpp"
#include "dynid/car/profile_check.hpp"
#include "dynid/car/progress_display.hpp"
#include "dynid/car/replay.hpp"
#include "dynid/car/socketcan_source.hpp"
#include "dynid/car/spool.hpp"
#include "dynid/car/uplink.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace {

using namespace dynid::car;
namespace input = dynid::input;
using namespace std::chrono_literals;

struct Options {
  std::string profile;
  std::string run;
  std::string cyclone_config;
  int domain = 0;
  std::vector<std::string> replay;  // the logs of one run
  std::string can;
  double speed = 1.0;
  bool fast = false;
  std::string spool;
  double drain_timeout = 60.0;
  double ack_timeout = 5.0;
  std::string chunks_out;
  std::uint64_t max_frames = 0;  // live: stop after this many frames (0: only on a signal)
  std::vector<std::string> sources;  // --source NAME=FILE
  bool check_profile = false;
};

// The replayed logs as paths, and as one name for messages ("a.log" or "a.MF4 + b.MF4").
std::vector<std::filesystem::path> replay_paths(const Options& options) {
  return {options.replay.begin(), options.replay.end()};
}

std::string replay_name(const Options& options) {
  std::string name;
  for (const auto& r : options.replay) name += (name.empty() ? "" : " + ") + r;
  return name;
}

constexpr const char* kLogPattern = "dynid-car %l: %v";

enum Exit { kOk = 0, kFailed = 1, kUndelivered = 2, kSpoolFull = 3, kInterrupted = 130 };

// Limits of the numeric options: beyond them a duration overflows its clock's count, or the
// value is a typing error (a replay 1000 times faster than real time is --fast anyway).
constexpr double kMinSpeed = 1e-3;
constexpr double kMaxSpeed = 1e3;
constexpr double kMaxSeconds = 86400.0;
constexpr double kMinAckTimeout = 0.01;
constexpr double kMaxFrames = 1e12;

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

// A run id names one recording: reusing one would mix two runs' chunks under one sequence.
void check_new_run(const Spool& spool, const std::string& vehicle, const std::string& run) {
  bool known = spool.acknowledged(vehicle, run).has_value();
  for (const auto& e : spool.pending_entries()) known = known || (e.vehicle == vehicle && e.run == run);
  if (known)
    throw dynid::InputError("run " + vehicle + "/" + run + " is already in the spool " + spool.file().string() +
                            " (its unacknowledged chunks are resent automatically): choose a new --run");
}

// The live bus's socket asks for a receive buffer of several seconds of a busy bus, so that a
// moment behind (a slow disk, a scheduler hiccup, the bus held for an auxiliary source) costs no
// frame; the kernel caps it at net.core.rmem_max (212992 bytes by default: ~250 frames; raise it
// with sysctl on the car: docs/DESIGN.md, "Auxiliary sources in a live run"). Drops are counted.
SocketCanOptions live_bus_options() {
  SocketCanOptions o;
  o.receive_buffer_bytes = 8 << 20;
  return o;
}

// What the DBC's parser passed over (messages it cannot use, ambiguous names, references to
// nothing): a profile that reads such a message or name is refused at load; the rest is said,
// not hidden.
void report_dbc_warnings(const VehicleProfile& profile) {
  constexpr std::size_t kShown = 5;
  const std::vector<std::string>& warnings = profile.dbc->warnings;
  if (warnings.empty()) return;
  spdlog::warn("{}: {} warning{} from the DBC parser", profile.dbc_path.filename().string(),
               warnings.size(), warnings.size() == 1 ? "" : "s");
  for (std::size_t i = 0; i < warnings.size() && i < kShown; ++i) spdlog::warn("  {}", warnings[i]);
  if (warnings.size() > kShown) spdlog::warn("  ... and {} more", warnings.size() - kShown);
}

// What the profile's loader passed over (vehicle_profile.hpp: constants nobody reads).
void report_profile_warnings(const VehicleProfile& profile) {
  for (const std::string& warning : profile.warnings) spdlog::warn("{}", warning);
}

// The profile of this run: the declared one with the auxiliary sources given (auxiliary.hpp),
// their clocks put on the bus's (an estimate reads the replayed log once), reported.
RunSources run_profile(const Options& options) {
  const VehicleProfile declared = load_vehicle_profile(options.profile);
  report_dbc_warnings(declared);
  report_profile_warnings(declared);
  std::map<std::string, std::filesystem::path> given;
  for (const auto& s : options.sources) {
    const std::size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == s.size())
      throw dynid::InputError("--source '" + dynid::input::printable(s) + "': expected NAME=FILE");
    if (!given.emplace(s.substr(0, eq), s.substr(eq + 1)).second)
      throw dynid::InputError("--source " + dynid::input::printable(s.substr(0, eq)) + " given twice");
  }
  std::optional<LogSource> bus;
  if (!options.replay.empty()) bus.emplace(replay_paths(options));
  const bool live = options.replay.empty() && !options.can.empty();
  // A second bus live: its interface, given in place of a log (--source chassis=can1).
  const LiveCanOpener open_can = [](const AuxiliarySourceSpec& spec, const std::string& interface, double offset) {
    return std::make_unique<CanInterfaceFollower>(spec, interface, offset);
  };
  RunSources run = prepare_sources(declared, given, bus ? &*bus : nullptr, live, open_can);
  for (const auto& r : run.reports) {
    spdlog::info("{}", r.describe());
    for (const auto& w : r.warnings) spdlog::warn("source '{}': {}", r.name, w);
  }
  return run;
}

// A model the server could not run on this run's channels is refused before anything is
// announced, spooled or written: otherwise the whole run streams and only the server says, at
// its end, "not run: the run has no channel ...".
void check_models(const Options& options, const VehicleProfile& profile) {
  const std::vector<std::string> lacking = models_lacking_channels(profile);
  if (lacking.empty()) return;
  std::string text =
      options.profile + ": " +
      (lacking.size() == 1 ? "a model" : std::to_string(lacking.size()) + " models") +
      " of [[models]] cannot run on this run's channels: ";
  for (std::size_t i = 0; i < lacking.size(); ++i) text += (i == 0 ? "" : "; ") + lacking[i];
  throw dynid::InputError(
      text +
      ". Map the channels in [[channels]] (or give the source that has them), or "
      "remove the model");
}

// What the run left out: the auxiliary samples outside the bus's time, the samples no chunk may
// carry, and the channels that made rows invalid, each named.
void log_left_out(const CarPipeline& pipe) {
  const AuxiliaryStats& a = pipe.auxiliary_stats();
  if (a.merged + a.before_bus + a.after_bus + a.out_of_range > 0)
    spdlog::info(
        "auxiliary sources: {} samples merged into the grid, {} before the first frame and {} "
        "after the "
        "last dropped",
        a.merged, a.before_bus, a.after_bus);
  for (const std::string& line : pipe.dropped_report()) spdlog::warn("{}", line);
  for (const std::string& line : pipe.missing_report()) spdlog::warn("{}", line);
}

// Lines of a log judged before anything of it is announced, spooled or written: enough to tell
// a log from another file at once, few enough that the probe costs nothing (about 5 ms). And the
// bytes it reads at most: a long line is one bad line however long, so only this bounds the look
// at a file without newlines (a sparse file); it passes a junk line of 100 MB (0.1 s to skip).
constexpr std::uint64_t kProbeLines = 10000;
constexpr std::uint64_t kProbeBytes = 256ull << 20;

// "<file>: <reason>", with what the file looks like when most of it is no frame (a CSV table, a
// compressed or binary file: can/log_content.hpp) and the first bad line's reason when there is
// one.
std::string log_problem(const Options& options, const LogSource& source,
                        const ReplayProgress& counts, const std::string& problem) {
  const auto errors = source.errors();
  // What each file looks like when most of the replay is no frame (a single file: no prefix).
  std::string looks;
  if (mostly_not_frames(counts))
    for (const std::string& file : options.replay)
      if (const std::string d = dynid::can::describe_log_file(file); !d.empty())
        looks += (looks.empty() ? "" : "; ") + (options.replay.size() > 1 ? file + ": " : "") + d;
  return replay_name(options) + ": not a CAN log this profile can use: " + problem +
         (looks.empty() ? "" : "; " + looks) + (errors.empty() ? "" : "; first: " + errors.front());
}

// A file the replay would make nothing of fails here, before any state changes.
void probe_log(const Options& options, const VehicleProfile& profile) {
  LogSource source(replay_paths(options), kProbeLines, kProbeBytes);
  const ReplayProgress counts = probe(source, profile, kProbeLines);
  const std::string problem = replay_problem(counts);
  if (!problem.empty())
    throw dynid::InputError(log_problem(options, source, counts,
                                        problem + " in its first " + std::to_string(kProbeLines) +
                                            " lines (at most " + std::to_string(kProbeBytes >> 20) +
                                            " MiB)"));
}

// Replays options.replay into the pipeline (finished at the end); on_progress as ReplayOptions'.
// Returns replay_problem() of the whole log as "<file>: <reason>", or "".
std::string replay_log(const Options& options, CarPipeline& pipe,
                       std::function<void(const ReplayProgress&)> on_progress) {
  LogSource source(replay_paths(options));
  ReplayOptions ro;
  ro.speed = options.fast ? 0.0 : options.speed;
  ro.progress_interval = 100ms;  // also how often acknowledgements are taken while replaying
  ro.on_progress = std::move(on_progress);
  const ReplayProgress done = replay(source, pipe, ro);
  for (const auto& note : source.notes()) spdlog::info("{}", note);  // what was recovered (MDF4)
  log_left_out(pipe);
  if (done.rows > 0)  // where the run's times (row / rate) sit on the log's clock, e.g. to compare with its GNSS
    spdlog::info("grid row 0 is at {:.6f} s of the log's clock", pipe.origin());
  spdlog::info("replay done: {} frames ({} bad lines, {} unknown ids, {} timestamps out of range)",
               done.frames, source.bad_input(), done.unknown_id, pipe.mapper_stats().bad_time);
  spdlog::info("the log: {:.1f} s, {} jumps of its clock, {} chunks", done.log_seconds,
               pipe.resampler_stats().pieces_ended, done.chunks);
  for (const auto& e : source.errors()) spdlog::warn("{}", e);
  const std::string problem = replay_problem(done);
  return problem.empty() ? problem : log_problem(options, source, done, problem);
}

// Reads the bus (options.can, opened by the caller) live into the pipeline until a signal (or
// options.max_frames frames), then finishes it. `service` runs about every 100 ms
// (acknowledgements, progress). Both the delivering client and --chunks-out read the bus
// through this loop.
void read_bus(const Options& options, SocketCanSource& source, CarPipeline& pipe, std::vector<FollowedSource> followed,
              const std::function<void(const CarPipeline&)>& service) {
  LiveMerge merge(pipe, std::move(followed), [](const std::string& stop) { spdlog::error("{}", stop); });
  const auto wall_now = [] {  // the clock of the kernel's receive times
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  };
  g_live.store(&source);
  struct Unregister {
    ~Unregister() { g_live.store(nullptr); }
  } unregister;
  // After the bind: a script may start sending once it sees this line.
  spdlog::info("reading {} live", options.can);
  dynid::can::Frame frame;
  auto next_service = std::chrono::steady_clock::now();
  for (;;) {
    const NextStatus status = source.next(frame, 100ms);
    if (status == NextStatus::End) break;
    if (status == NextStatus::Frame) {
      frame.timestamp = live_timestamp(frame.timestamp);
      merge.on_frame(frame, wall_now());
      if (options.max_frames > 0 && source.frames() >= options.max_frames) break;
    }
    // No frame: the grid clock still moves (receive times are CLOCK_REALTIME), so rows leave.
    if (status == NextStatus::Timeout) merge.idle(wall_now());
    if (std::chrono::steady_clock::now() >= next_service) {
      merge.service(wall_now());
      service(pipe);
      next_service = std::chrono::steady_clock::now() + 100ms;
    }
  }
  merge.finish(wall_now);
  for (const auto& line : merge.report()) spdlog::info("{}", line);
  if (merge.stats().frames_forced > 0)
    spdlog::warn("{} frames let in at the end of a source's wait, a source behind them: the run's chunks may differ "
                 "from a replay of the same files", merge.stats().frames_forced);
  log_left_out(pipe);
  spdlog::info("bus {} closed: {} frames, {} error frames, {} dropped by the kernel, {} chunks", options.can,
               source.frames(), source.error_frames(), source.dropped(), pipe.chunks());
}

struct Session {
  const Options& options;
  const VehicleProfile& profile;
  std::vector<AuxiliarySample> auxiliary;  // into the run's one pipeline
  std::vector<FollowedSource> followed;    // live: the sources read while the bus is
  Spool& spool;
  Delivery& delivery;
  ProgressDisplay& display;
  bool spool_full = false;
  std::string unusable_log = {};  // of a replayed log judged unusable at its end (replay_log)
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
    CarPipeline pipe(profile, run, [this](dynid::ingest::Chunk&& chunk) {
      delivery.submit(chunk);
      if (g_stop.load()) throw Interrupted{};
    });
    pipe.add_auxiliary(std::move(auxiliary));
    return pipe;
  }

  void replay_run(const std::string& run) {
    CarPipeline pipe = pipeline(run);
    source_name = LogSource(replay_paths(options)).name();
    unusable_log = replay_log(options, pipe, [&](const ReplayProgress& p) {
      delivery.service(0ms);
      show(p, p.done);
      if (g_stop.load()) throw Interrupted{};
    });
  }

  void read_bus_run(const std::string& run) {
    CarPipeline pipe = pipeline(run);
    source_name = "live " + options.can;
    SocketCanSource source(options.can, live_bus_options());
    read_bus(options, source, pipe, std::move(followed), [&](const CarPipeline& p) {
      delivery.service(0ms);
      ReplayProgress progress;
      progress.frames = p.mapper_stats().frames;
      progress.fraction = -1.0;
      show(progress);
    });
  }

  void read_source() {
    const std::string run = options.run.empty() ? default_run_id() : options.run;
    check_new_run(spool, profile.vehicle, run);
    delivery.announce(profile.announcement(run));
    spdlog::info("run {}/{}: {} channels, {} Hz, {} rows a chunk", profile.vehicle, run,
                 profile.channels.size(), profile.rate_hz, profile.chunk_rows);
    // A replay can wait a moment until the server has taken the announcement (it answers with a
    // receipt), so the first chunks neither go into the void nor overtake the announcement
    // (both would be resent anyway); a live bus cannot wait.
    if (!options.replay.empty() && !wait_for_server(run, 3s))
      spdlog::warn("no server took the announcement within 3 s: spooling, and sending when one appears");
    try {
      if (!options.replay.empty()) replay_run(run);
      else read_bus_run(run);
    } catch (const SpoolFull& e) {
      // Stop reading rather than drop anything: what is stored is still delivered below.
      spool_full = true;
      display.finish();
      spdlog::error("{}; stopped reading {} — the rest of the run is not recorded", e.what(),
                    options.replay.empty() ? options.can : replay_name(options));
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

// --chunks-out: the same reading and pipeline, the chunks written to a file instead of delivered.
int write_chunks(const Options& options) {
  RunSources sources = run_profile(options);
  const VehicleProfile& profile = sources.profile;
  check_models(options, profile);
  if (!options.replay.empty()) probe_log(options, profile);
  // The source is opened before the chunk file is created: a bus that cannot be read leaves none.
  std::optional<SocketCanSource> live;
  if (options.replay.empty()) live.emplace(options.can, live_bus_options());
  const std::string run = options.run.empty() ? default_run_id() : options.run;
  ChunkFileWriter writer(options.chunks_out);
  CarPipeline pipe(profile, run, [&writer](dynid::ingest::Chunk&& chunk) { writer.write(chunk); });
  pipe.add_auxiliary(std::move(sources.samples));
  spdlog::info("run {}/{}: {} channels, {} Hz, {} rows a chunk", profile.vehicle, run,
               profile.channels.size(), profile.rate_hz, profile.chunk_rows);
  spdlog::info("chunks to {}", options.chunks_out);
  std::string problem;
  try {
    if (!options.replay.empty()) {
      problem = replay_log(options, pipe, [](const ReplayProgress&) {
        if (g_stop.load()) throw Interrupted{};
      });
    } else {
      read_bus(options, *live, pipe, std::move(sources.followed), [](const CarPipeline&) {});
    }
  } catch (const Interrupted&) {
    spdlog::warn("interrupted: {} chunks written to {}", writer.chunks(), options.chunks_out);
    return kInterrupted;
  }
  spdlog::info("{} chunks ({} rows, {} invalid) written to {}", writer.chunks(), pipe.resampler_stats().rows,
               pipe.resampler_stats().invalid_rows, options.chunks_out);
  if (!problem.empty()) {
    spdlog::error("{}", problem);
    return kFailed;
  }
  return g_stop.load() ? kInterrupted : kOk;
}

// --check-profile: which models the profile can run and why not; with --replay, the log read
// through the same pipeline (nothing spooled or sent) and each channel's rate and health
// (profile_check.hpp). The report on stdout; exit 1 when a model cannot run.
int check_profile_and_log(const Options& options) {
  RunSources sources = run_profile(options);
  const VehicleProfile& profile = sources.profile;
  ProfileCheck check = dynid::car::check_profile(profile);
  if (!options.replay.empty()) {
    probe_log(options, profile);
    std::vector<dynid::ingest::Chunk> chunks;
    CarPipeline pipe(
        profile, options.run.empty() ? "check" : options.run,
        [&chunks](dynid::ingest::Chunk&& chunk) { chunks.push_back(std::move(chunk)); });
    pipe.add_auxiliary(std::move(sources.samples));
    Options fast = options;
    fast.fast = true;  // a check reads the log at once, whatever --speed says
    const std::string problem = replay_log(fast, pipe, [](const ReplayProgress&) {
      if (g_stop.load()) throw Interrupted{};
    });
    if (!problem.empty()) spdlog::warn("{}", problem);
    dynid::car::check_log(check, profile, replay_name(options), pipe, chunks);
  }
  std::fputs(check.text().c_str(), stdout);
  return check.runs() ? kOk : kFailed;
}

int run(const Options& options, ProgressDisplay& display) {
  // Every input is checked before the spool is touched.
  const std::string cyclone_config = dynid::dds::config_uri(options.cyclone_config);
  RunSources sources = run_profile(options);
  const VehicleProfile& profile = sources.profile;
  if (!options.replay.empty() || !options.can.empty()) check_models(options, profile);  // a new run
  if (!options.replay.empty()) probe_log(options, profile);
  const std::filesystem::path spool_dir = options.spool.empty() ? profile.spool_directory : std::filesystem::path(options.spool);
  Spool spool(spool_dir, profile.spool_max_bytes);
  spdlog::info("spool {}: {} chunks pending", spool.file().string(), spool.count());

  dynid::dds::Participant participant({static_cast<dds_domainid_t>(options.domain), cyclone_config});
  Uplink uplink(participant, profile.vehicle);
  DeliveryOptions delivery_options;
  delivery_options.ack_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(options.ack_timeout));
  Delivery delivery(spool, uplink, delivery_options, [](LogLevel level, const std::string& message) {
    spdlog::log(level == LogLevel::info ? spdlog::level::info
                : level == LogLevel::warning ? spdlog::level::warn : spdlog::level::err, "{}", message);
  });


  Session session{options, profile, std::move(sources.samples), std::move(sources.followed), spool, delivery, display};
  if (!options.replay.empty() || !options.can.empty()) session.read_source();
  const bool drained = session.drain();
  const auto& s = delivery.stats();
  for (const std::string& line : delivery.set_aside_report()) spdlog::warn("{}", line);
  if (uplink.bad_receipts() > 0)
    spdlog::warn("{} malformed acknowledgements ignored, last: {}", uplink.bad_receipts(), uplink.last_bad_receipt());
  if (!drained) {
    spdlog::error("not everything was acknowledged within {} s: {}; it stays in {} and is resent on the next start",
                  options.drain_timeout, delivery.holdup(), spool.file().string());
    return session.spool_full ? kSpoolFull : kUndelivered;
  }
  spdlog::info(
      "all chunks acknowledged: {} stored, {} sent, {} resent{}, {} rejected, {} set aside",
      s.submitted, s.sent, s.resent,
      s.resent == 0 ? "" : fmt::format(" in {} rounds", s.resend_rounds), s.rejections,
      s.set_aside);
  if (!session.unusable_log.empty()) {  // what was good is delivered; the job was not done
    spdlog::error("{}", session.unusable_log);
    return kFailed;
  }
  if (session.spool_full) return kSpoolFull;
  return g_stop.load() ? kInterrupted : kOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynid-car: reads the CAN bus or replays a log and delivers the run's chunks to dynid-server"};
  Options o;
  app.add_option("--profile", o.profile, "vehicle profile (TOML)")->required()->check(input::input_file("vehicle profile"));
  app.add_option("--run", o.run, "run id (default: run-<UTC time>)")->check(input::id("run name"));
  app.add_option(
         "--cyclone-config", o.cyclone_config,
         "Cyclone DDS configuration: a file (deploy/cyclonedds/*.xml), or file:// URIs and XML "
         "fragments, comma-separated, as in CYCLONEDDS_URI; or $DYNID_CYCLONE_CONFIG "
         "(required unless --chunks-out)")
      ->envname("DYNID_CYCLONE_CONFIG");
  app.add_option("--domain", o.domain, "DDS domain id")->check(CLI::Range(0, 230));
  auto* replay_opt =
      app.add_option(
             "--replay", o.replay,
             "replay this CAN log (candump -l, Vector ASC or BLF, PCAN trace, ASAM MDF4, told by "
             "its content); several files (--replay a b, or --replay given again) are one run, "
             "merged in time order")
          ->check(input::input_file("CAN log"));
  auto* can_opt = app.add_option("--can", o.can, "read this SocketCAN interface live (e.g. can0)");
  replay_opt->excludes(can_opt);
  auto* speed_opt = app.add_option("--speed", o.speed, "replay speed (1 = real time)")
                        ->check(input::within(kMinSpeed, kMaxSpeed))->needs(replay_opt);
  app.add_flag("--fast", o.fast, "replay as fast as possible")->needs(replay_opt)->excludes(speed_opt);
  app.add_option("--chunks-out", o.chunks_out,
                 "no server: write the run's chunks to this file (length-prefixed "
                 "encode_chunk records) and exit")
      ->check(input::output_file("chunk file"));
  app.add_option("--source", o.sources,
                 "NAME=FILE: the file of the profile's auxiliary source NAME for this run (repeatable; "
                 "overrides the profile's file)");
  app.add_option("--max-frames", o.max_frames, "live: stop after this many frames")
      ->check(input::within(1, kMaxFrames))->needs(can_opt);
  app.add_flag(
         "--check-profile", o.check_profile,
         "send nothing: say which of the profile's models can run and why not; with --replay, "
         "also each channel's rate, gaps and health on that log, and which models it can judge "
         "(exit 1 when a model cannot run)")
      ->excludes(can_opt);
  app.add_option("--spool", o.spool, "spool folder (default: the profile's [spool] directory)");
  app.add_option("--drain-timeout", o.drain_timeout, "seconds to wait for the last acknowledgements")
      ->check(input::within(0.0, kMaxSeconds));
  app.add_option("--ack-timeout", o.ack_timeout, "seconds without acknowledgement before resending")
      ->check(input::within(kMinAckTimeout, kMaxSeconds));
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kFailed;
  }
  if (o.check_profile && !o.chunks_out.empty()) {
    std::fprintf(stderr,
                 "dynid-car: --check-profile sends and writes nothing: drop --chunks-out\n");
    return kFailed;
  }
  if (!o.chunks_out.empty() && o.replay.empty() && o.can.empty()) {
    std::fprintf(stderr, "dynid-car: --chunks-out needs --replay or --can\n");
    return kFailed;
  }
  if (o.chunks_out.empty() && o.cyclone_config.empty() && !o.check_profile) {
    std::fprintf(stderr, "dynid-car: --cyclone-config is required (unless --chunks-out)\n");
    return kFailed;
  }

  // Everything on stderr, through the display so log lines never tear the progress line.
  ProgressDisplay display(stderr, isatty(STDERR_FILENO) != 0);
  spdlog::default_logger()->sinks().clear();
  spdlog::default_logger()->sinks().push_back(display.log_sink());
  spdlog::set_pattern(kLogPattern);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    if (o.check_profile) {
      const int status = check_profile_and_log(o);
      display.finish();
      return status;
    }
    if (!o.chunks_out.empty()) {
      const int status = write_chunks(o);
      display.finish();
      return status;
    }
    return run(o, display);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kFailed;
  }
}
