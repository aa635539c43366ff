#include "dynid/car/pipeline.hpp"

#include <algorithm>
#include <cmath>

namespace dynid::car {
namespace {

ResamplerConfig resampler_config(const VehicleProfile& p) {
  ResamplerConfig c;
  c.rate_hz = p.rate_hz;
  c.channels = p.channels.size();
  c.max_gap_periods = p.max_gap_periods;
  for (const auto& m : p.channels) {
    c.max_gap.push_back(m.max_gap);
    c.interpolation.push_back(m.interpolation);
  }
  c.jumps.forward = p.max_time_jump;
  c.jumps.backward = c.max_latency;  // older frames could only join rows already emitted
  return c;
}

}  // namespace

CarPipeline::CarPipeline(const VehicleProfile& profile, const std::string& run,
                         ChunkBuilder::ChunkSink sink, std::uint64_t first_sequence)
    : profile_(profile),
      time_jumps_(resampler_config(profile).jumps),
      mapper_(profile),
      builder_(profile.vehicle, run, profile.channels.size(), profile.chunk_rows, std::move(sink),
               first_sequence),
      resampler_(resampler_config(profile),
                 [this](std::uint64_t k, std::span<const double> row, bool valid) {
                   builder_.add_row(k, row, valid);
                 }) {}

double CarPipeline::run_time(double source_time) {
  if (!first_time_) first_time_ = source_time;
  return static_cast<double>(std::llround((source_time - *first_time_) * 1e6)) / 1e6;
}

void CarPipeline::add_auxiliary(std::vector<AuxiliarySample> samples) {
  aux_ = std::move(samples);
  aux_next_ = 0;
}

void CarPipeline::append_auxiliary(std::vector<AuxiliarySample> samples) {
  // What was pushed already goes, so a long live run keeps only what is still to come.
  aux_.erase(aux_.begin(), aux_.begin() + static_cast<std::ptrdiff_t>(aux_next_));
  aux_next_ = 0;
  aux_.insert(aux_.end(), std::make_move_iterator(samples.begin()), std::make_move_iterator(samples.end()));
}

// Auxiliary samples up to `source_time` into the resampler (those before the first frame dropped).
void CarPipeline::push_auxiliary_until(double source_time) {
  for (; aux_next_ < aux_.size() && aux_[aux_next_].time <= source_time; ++aux_next_) {
    const AuxiliarySample& a = aux_[aux_next_];
    if (!first_time_ || a.time < *first_time_) {
      ++aux_stats_.before_bus;
      continue;
    }
    if (!aux_dropped_.keep(a.channel, a.time, a.value)) {
      ++aux_stats_.out_of_range;
      continue;
    }
    resampler_.push(a.channel, run_time(a.time), a.value);
    ++aux_stats_.merged;
  }
}

void CarPipeline::on_frame(const can::Frame& frame) {
  samples_.clear();
  if (mapper_.map(frame, samples_) == FrameOutcome::BadTime) return;  // not a time the grid can hold
  const double t = run_time(frame.timestamp);
  last_time_ = std::max(last_time_, frame.timestamp);
  if (aux_next_ < aux_.size()) push_auxiliary_until(frame.timestamp);
  for (const auto& s : samples_) resampler_.push(s.channel, t, s.value);
  // Every frame moves the clock, so a silent channel is declared stale in time.
  resampler_.advance_clock(t);
}

std::vector<std::string> CarPipeline::dropped_report() const {
  std::vector<std::string> out = mapper_.dropped().report(profile_, "the bus");
  for (std::string& line : aux_dropped_.report(profile_, "the bus"))
    out.push_back("auxiliary " + line);
  return out;
}

std::vector<std::string> CarPipeline::missing_report() const {
  const ResamplerStats& r = resampler_.stats();
  std::vector<std::pair<std::uint64_t, std::size_t>> order;  // (rows missing, channel)
  for (std::size_t c = 0; c < r.missing_by_channel.size() && c < profile_.channels.size(); ++c) {
    const std::uint64_t missing = r.missing_by_channel[c];
    if (missing >= 10 && 100 * missing >= r.rows) order.emplace_back(missing, c);
  }
  std::sort(order.rbegin(), order.rend());
  std::vector<std::string> out;
  for (const auto& [missing, c] : order) {
    const ChannelMapping& m = profile_.channels[c];
    std::string from;
    if (m.constant) {
      from = "the profile's constant, which comes with every mapped frame: no channel had one";
    } else if (m.source && *m.source < profile_.sources.size()) {
      from = "auxiliary source '" + profile_.sources[*m.source].name + "'";
    } else {
      from = "message '" + m.message + "', signal";
      for (std::size_t i = 0; i < m.inputs.size(); ++i)
        from += (i == 0 ? " " : ", ") + m.inputs[i].signal;
    }
    out.push_back("channel '" + m.channel + "' had no value in " + std::to_string(missing) +
                  " of " + std::to_string(r.rows) + " rows (" +
                  (missing >= r.rows ? "no sample at all from " : "from ") + from +
                  "): those rows are invalid");
  }
  return out;
}

void CarPipeline::idle(double time) {
  if (first_time_) resampler_.idle(run_time(time));
}

void CarPipeline::finish() {
  if (first_time_) push_auxiliary_until(last_time_);
  aux_stats_.after_bus += aux_.size() - aux_next_;
  aux_next_ = aux_.size();
  resampler_.finish();
  builder_.flush();
}

}  // namespace dynid::car
