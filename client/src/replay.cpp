#include "dynid/car/replay.hpp"

#include <thread>

namespace dynid::car {
namespace {

using Clock = std::chrono::steady_clock;

ReplayProgress snapshot(const FrameSource& source, const CarPipeline& pipeline, double log_seconds) {
  const MapStats& m = pipeline.mapper_stats();
  const ResamplerStats& r = pipeline.resampler_stats();
  ReplayProgress p;
  p.frames = m.frames;
  p.decoded = m.decoded();
  p.unknown_id = m.unknown_id;
  p.bad = source.bad_input() + m.short_payload + m.remote + m.non_finite;
  p.other_interface = m.other_interface;
  p.rows = r.rows;
  p.invalid_rows = r.invalid_rows;
  p.chunks = pipeline.chunks();
  p.fraction = source.fraction_done();
  p.log_seconds = log_seconds;
  return p;
}

}  // namespace

ReplayProgress replay(FrameSource& source, CarPipeline& pipeline, const ReplayOptions& options) {
  can::Frame frame;
  bool first = true;
  double t0 = 0.0;
  double log_seconds = 0.0;
  const auto start = Clock::now();
  auto next_report = start + options.progress_interval;
  while (source.next(frame, std::chrono::milliseconds(0)) == NextStatus::Frame) {
    if (first) t0 = frame.timestamp;
    first = false;
    const double elapsed = frame.timestamp - t0;
    if (options.max_log_seconds && elapsed > *options.max_log_seconds) break;
    log_seconds = std::max(log_seconds, elapsed);
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

}  // namespace dynid::car
