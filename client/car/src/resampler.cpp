#include "dynid/car/resampler.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/error.hpp"

namespace dynid::car {
namespace {

void check_config(const ResamplerConfig& c) {
  if (!(c.rate_hz > 0.0) || !std::isfinite(c.rate_hz)) throw InputError("resampler: rate_hz must be > 0");
  if (c.channels == 0) throw InputError("resampler: no channel");
  if (!(c.max_gap_periods >= 1.0)) throw InputError("resampler: max_gap_periods must be >= 1");
  if (!(c.max_latency > 0.0)) throw InputError("resampler: max_latency must be > 0");
  if (!c.max_gap.empty() && c.max_gap.size() != c.channels)
    throw InputError("resampler: max_gap has " + std::to_string(c.max_gap.size()) + " entries for " +
                     std::to_string(c.channels) + " channels");
  if (!c.interpolation.empty() && c.interpolation.size() != c.channels)
    throw InputError("resampler: interpolation has " + std::to_string(c.interpolation.size()) + " entries for " +
                     std::to_string(c.channels) + " channels");
  for (const auto& g : c.max_gap)
    if (g && !(*g > 0.0)) throw InputError("resampler: a max_gap must be > 0");
}

}  // namespace

Resampler::Resampler(ResamplerConfig config, RowSink sink)
    : config_(std::move(config)), sink_(std::move(sink)), source_clock_(config_.jumps) {
  check_config(config_);
  if (config_.max_gap.empty()) config_.max_gap.resize(config_.channels);
  if (config_.interpolation.empty()) config_.interpolation.resize(config_.channels, Interpolation::kLinear);
  channels_.resize(config_.channels);
  row_.resize(config_.channels);
  stats_.missing_by_channel.assign(config_.channels, 0);
  stats_.samples_by_channel.assign(config_.channels, 0);
  origin_ = first_origin_ = config_.origin;
}

double Resampler::row_time(std::uint64_t k) const {
  return *origin_ + static_cast<double>(k - piece_first_row_) / config_.rate_hz;
}

// Every frame time goes through the source clock: a jump ends the piece before the time is used.
void Resampler::observe(double time) {
  if (source_clock_.step(time)) end_piece();
}

void Resampler::start_piece(double time) {
  origin_ = time;
  if (!first_origin_) first_origin_ = time;
  piece_first_row_ = next_row_;
}

void Resampler::end_piece() {
  if (origin_) {
    emit_reached();
    if (last_valid_) {  // the break, so that no valid segment spans it
      for (auto& missing : stats_.missing_by_channel) ++missing;
      deliver(false);
    }
    ++stats_.pieces_ended;
  }
  origin_.reset();
  std::fill(channels_.begin(), channels_.end(), Channel{});
  clock_ = frame_clock_ = -std::numeric_limits<double>::infinity();
}

void Resampler::push(std::size_t channel, double time, double value) {
  ++stats_.samples;
  if (channel < stats_.samples_by_channel.size()) ++stats_.samples_by_channel[channel];
  observe(time);
  if (!origin_) start_piece(time);
  Channel& c = channels_.at(channel);
  if (!c.samples.empty() && !(time > c.samples.back().time)) {
    ++stats_.out_of_order;
    return;
  }
  bool bridgeable = false;
  if (!c.samples.empty()) {
    const double interval = time - c.samples.back().time;
    bridgeable = interval <= judge_interval(channel, c, interval);
  }
  c.samples.push_back({time, value, bridgeable});
  clock_ = std::max(clock_, time);
  frame_clock_ = std::max(frame_clock_, time);
  emit_ready();
}

void Resampler::advance_clock(double time) {
  observe(time);
  clock_ = std::max(clock_, time);
  frame_clock_ = std::max(frame_clock_, time);
  emit_ready();
}

void Resampler::idle(double time) {
  if (origin_ && source_clock_.silent_at(time)) end_piece();
  clock_ = std::max(clock_, time);
  emit_ready();
}

// Records the interval and returns G_c for it: the override, or max_gap_periods x the lower
// median of the recent intervals including this one (0 = not enough history to judge).
double Resampler::judge_interval(std::size_t channel, Channel& c, double interval) {
  c.intervals[c.interval_count % kPeriodWindow] = interval;
  ++c.interval_count;
  if (config_.max_gap[channel]) return *config_.max_gap[channel];
  if (c.interval_count < kMinIntervals) return 0.0;
  const std::size_t n = std::min(c.interval_count, kPeriodWindow);
  std::array<double, kPeriodWindow> sorted = c.intervals;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>((n - 1) / 2),
                   sorted.begin() + static_cast<long>(n));
  return config_.max_gap_periods * sorted[(n - 1) / 2];
}

// How long after its last sample a channel can no longer bridge anything. A lower median of
// the window plus one more interval never exceeds the window's maximum, so past
// max_gap_periods x max(window) the next interval cannot be judged bridgeable: the stale
// verdict agrees with the interpolation rule whatever arrives later.
double Resampler::stale_after(std::size_t channel, const Channel& c) const {
  if (config_.max_gap[channel]) return *config_.max_gap[channel];
  if (c.interval_count + 1 < kMinIntervals) return 0.0;
  const std::size_t n = std::min(c.interval_count, kPeriodWindow);
  const double longest = *std::max_element(c.intervals.begin(), c.intervals.begin() + static_cast<long>(n));
  return config_.max_gap_periods * longest;
}

bool Resampler::decided(std::size_t channel, double t) const {
  const Channel& c = channels_[channel];
  if (!c.samples.empty() && c.samples.back().time >= t) {
    if (config_.interpolation[channel] == Interpolation::kLinear) return true;
    // Cubic: b's successor gives b's slope (header); waited for by the frames' clock.
    const auto b = std::lower_bound(c.samples.begin(), c.samples.end(), t,
                                    [](const Sample& s, double x) { return s.time < x; });
    if (b->time == t || std::next(b) != c.samples.end()) return true;
    if (clock_ > t + config_.max_latency) return true;
    return frame_clock_ > b->time + stale_after(channel, c);
  }
  // Verdicts of "missing" only for times the source clock has reached, so that a stream whose
  // channels are all stale does not run ahead of its own data.
  if (t > clock_) return false;
  if (clock_ > t + config_.max_latency) return true;
  return !c.samples.empty() && clock_ > c.samples.back().time + stale_after(channel, c);
}

std::optional<double> Resampler::value_at(std::size_t channel, double t) const {
  const Channel& c = channels_[channel];
  const auto b = std::lower_bound(c.samples.begin(), c.samples.end(), t,
                                  [](const Sample& s, double x) { return s.time < x; });
  if (b == c.samples.end()) return std::nullopt;  // past the last sample: no extrapolation
  if (b->time == t) return b->value;
  if (b == c.samples.begin() || !b->bridgeable) return std::nullopt;  // before data, or a gap
  const auto a = std::prev(b);
  const double h = b->time - a->time;
  const double u = (t - a->time) / h;
  if (config_.interpolation[channel] == Interpolation::kLinear) return a->value + (b->value - a->value) * u;
  // Cubic Hermite; each end's slope from the parabola through it and its neighbours (header).
  const double secant = (b->value - a->value) / h;
  double slope_a = secant;
  double slope_b = secant;
  if (a != c.samples.begin() && a->bridgeable) {
    const auto before = std::prev(a);
    const double h0 = a->time - before->time;
    slope_a = ((a->value - before->value) / h0 * h + secant * h0) / (h0 + h);
  }
  if (const auto after = std::next(b); after != c.samples.end() && after->bridgeable) {
    const double h1 = after->time - b->time;
    slope_b = (secant * h1 + (after->value - b->value) / h1 * h) / (h + h1);
  }
  const double u2 = u * u;
  const double u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * a->value + (u3 - 2 * u2 + u) * h * slope_a + (3 * u2 - 2 * u3) * b->value +
         (u3 - u2) * h * slope_b;
}

void Resampler::emit_ready() {
  if (!origin_) return;
  for (;;) {
    const double t = row_time(next_row_);
    for (std::size_t i = 0; i < channels_.size(); ++i)
      if (!decided(i, t)) return;
    emit_row(t);
  }
}

void Resampler::finish() { emit_reached(); }

// The rows every channel with data has reached (the end of a run or of a piece).
void Resampler::emit_reached() {
  if (!origin_) return;
  emit_ready();
  double end = 0.0;
  bool any = false;
  for (const auto& c : channels_) {
    if (c.samples.empty()) continue;
    end = any ? std::min(end, c.samples.back().time) : c.samples.back().time;
    any = true;
  }
  while (any && row_time(next_row_) <= end) emit_row(row_time(next_row_));
}

void Resampler::emit_row(double t) {
  bool valid = true;
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    const auto v = value_at(i, t);
    row_[i] = v.value_or(0.0);
    if (!v) {
      valid = false;
      ++stats_.missing_by_channel[i];
    }
  }
  deliver(valid);
  const double next = row_time(next_row_);
  for (auto& c : channels_) prune(c, next);
}

void Resampler::deliver(bool valid) {
  if (!valid) std::fill(row_.begin(), row_.end(), 0.0);  // an invalid row carries zeros
  ++stats_.rows;
  if (!valid) ++stats_.invalid_rows;
  last_valid_ = valid;
  sink_(next_row_, row_, valid);
  ++next_row_;
}

// Keeps the last two samples at or before `t` (the lower bracket of the next row and, for a
// cubic channel, its predecessor) and all after it.
void Resampler::prune(Channel& c, double t) {
  while (c.samples.size() >= 3 && c.samples[2].time <= t) c.samples.pop_front();
}

}  // namespace dynid::car
