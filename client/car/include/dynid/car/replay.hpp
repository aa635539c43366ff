#pragma once
// Replay: drive a CarPipeline from a FrameSource (normally a candump log), as fast as possible
// or paced on the log's own clock, reporting progress.
//
// Contract:
// - Log time is the log's clock in pieces (source_clock.hpp, with the pipeline's time_jumps()):
//   the time the frames cover, a jump of the clock forwards or backwards counting nothing.
// - speed <= 0: as fast as possible. speed > 0: frame i is fed no earlier than
//   start + (log time of frame i) / speed on the steady clock (1 = real time), so 1 s of log
//   takes ~1 s, and a jump of the log's clock, whatever its size, is not waited for.
// - max_log_seconds stops after that much log time; the pipeline is finished either way (final
//   partial chunk emitted).
// - on_progress is called about every progress_interval of wall time and once at the end (with
//   done = true). Bad lines, unknown ids, short frames and other buses are counted, never sent.
// - Exceptions from the sink (e.g. the spool is full) propagate: the replay stops there, and the
//   chunks already handed over stay where the sink put them.
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "dynid/car/frame_source.hpp"
#include "dynid/car/pipeline.hpp"

namespace dynid::car {

struct ReplayProgress {
  std::uint64_t frames = 0;           ///< good frames read from the source
  std::uint64_t bad_lines = 0;        ///< input the source found malformed (bad log lines)
  std::uint64_t decoded = 0;          ///< frames the DBC decoded (mapped or not)
  std::uint64_t mapped = 0;           ///< frames that gave a channel of the profile
  std::uint64_t unknown_id = 0;
  std::uint64_t bad = 0;  ///< bad lines + short payloads + remote frames + NaN values + bad times
  std::uint64_t other_interface = 0;  ///< frames of buses the profile ignores
  std::uint64_t rows = 0;
  std::uint64_t invalid_rows = 0;
  std::uint64_t chunks = 0;
  double fraction = 0.0;      ///< of the file, [0, 1]; negative for a live source
  double log_seconds = 0.0;   ///< log time replayed
  bool done = false;
};

struct ReplayOptions {
  double speed = 0.0;
  std::optional<double> max_log_seconds;
  std::chrono::milliseconds progress_interval{1000};
  std::function<void(const ReplayProgress&)> on_progress;
};

ReplayProgress replay(FrameSource& source, CarPipeline& pipeline, const ReplayOptions& options = {});

/// Why a source with these counts is no log the profile can be identified from, or "" when it
/// is one: no frame at all, no frame that gives a channel of the profile, or more bad lines than
/// frames (a file of another format, or corrupted).
std::string replay_problem(const ReplayProgress& counts);

/// True when most of what the source read is no frame (no frame at all, or more bad lines than
/// frames): the verdicts of replay_problem() after which the file is described by what it looks
/// like (can/log_content.hpp), since it is likely no log of a format read here.
bool mostly_not_frames(const ReplayProgress& counts);

/// The counts of the source's first `lines` lines (frames + bad input) as a replay with
/// `profile` would count them, nothing cut or sent: replay_problem() of a probe refuses a file
/// that is not a usable log before anything of it is announced, spooled or written.
ReplayProgress probe(FrameSource& source, const VehicleProfile& profile, std::uint64_t lines);

}  // namespace dynid::car
