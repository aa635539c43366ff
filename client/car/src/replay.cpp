#include "dynid/car/replay.hpp"

#include <string>
#include <thread>
#include <vector>

#include "dynid/car/source_clock.hpp"

namespace dynid::car {
namespace {

using Clock = std::chrono::steady_clock;

// What the source and the mapper counted.
ReplayProgress counts(const FrameSource& source, const MapStats& m) {
  ReplayProgress p;
  p.frames = m.frames;
  p.bad_lines = source.bad_input();
  p.decoded = m.decoded();
  p.mapped = m.mapped;
  p.unknown_id = m.unknown_id;
  p.bad =
      source.bad_input() + m.short_payload + m.remote + m.non_finite + m.out_of_range + m.bad_time;
  p.other_interface = m.other_interface;
  p.fraction = source.fraction_done();
  return p;
}

ReplayProgress snapshot(const FrameSource& source, const CarPipeline& pipeline, double log_seconds) {
  ReplayProgress p = counts(source, pipeline.mapper_stats());
  const ResamplerStats& r = pipeline.resampler_stats();
  p.rows = r.rows;
  p.invalid_rows = r.invalid_rows;
  p.chunks = pipeline.chunks();
  p.log_seconds = log_seconds;
  return p;
}

}  // namespace

ReplayProgress replay(FrameSource& source, CarPipeline& pipeline, const ReplayOptions& options) {
  can::Frame frame;
  // The log's clock in pieces, as the resampler cuts it: a jump neither waits nor counts.
  SourceClock log_clock(pipeline.time_jumps());
  double log_seconds = 0.0;
  const auto start = Clock::now();
  auto next_report = start + options.progress_interval;
  while (source.next(frame, std::chrono::milliseconds(0)) == NextStatus::Frame) {
    if (usable_time(frame.timestamp)) log_clock.step(frame.timestamp);  // else the mapper drops it
    const double elapsed = log_clock.elapsed();
    if (options.max_log_seconds && elapsed > *options.max_log_seconds) break;
    log_seconds = elapsed;
    if (options.speed > 0.0)  // pace on the log's clock; a backwards timestamp does not wait
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(elapsed / options.speed)));
    pipeline.on_frame(frame);
    if (options.on_progress && Clock::now() >= next_report) {
      options.on_progress(snapshot(source, pipeline, log_seconds));
      next_report = Clock::now() + options.progress_interval;
    }
  }
  pipeline.finish();
  ReplayProgress done = snapshot(source, pipeline, log_seconds);
  done.done = true;
  if (options.on_progress) options.on_progress(done);
  return done;
}

std::string replay_problem(const ReplayProgress& c) {
  if (c.frames == 0) return "no CAN frame (" + std::to_string(c.bad_lines) + " bad lines)";
  if (c.mapped == 0)
    return "none of its " + std::to_string(c.frames) + " frames gives a channel of the profile (" +
           std::to_string(c.decoded) + " decoded by its DBC, " + std::to_string(c.unknown_id) + " unknown ids, " +
           std::to_string(c.other_interface) + " of other interfaces)";
  if (mostly_not_frames(c))
    return "most lines or objects are not CAN frames (" + std::to_string(c.bad_lines) + " bad lines, " +
           std::to_string(c.frames) + " frames)";
  return "";
}

bool mostly_not_frames(const ReplayProgress& c) {
  return c.frames == 0 || c.bad_lines > c.frames;
}

ReplayProgress probe(FrameSource& source, const VehicleProfile& profile, std::uint64_t lines) {
  SignalMapper mapper(profile);
  std::vector<ChannelSample> samples;
  can::Frame frame;
  while (mapper.stats().frames + source.bad_input() < lines &&
         source.next(frame, std::chrono::milliseconds(0)) == NextStatus::Frame) {
    samples.clear();
    mapper.map(frame, samples);
  }
  return counts(source, mapper.stats());
}

}  // namespace dynid::car
