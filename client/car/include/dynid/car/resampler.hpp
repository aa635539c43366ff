#pragma once
// Resampler: timestamped channel samples (irregular, per channel, as CAN delivers them) -> rows
// of a uniform grid t_k = origin + k / rate, streaming.
//
// Interpolation rule: the value of channel c at t_k is interpolated between the two samples a, b
// of c with t_a <= t_k <= t_b (the sample itself when t_a == t_k), provided that t_b - t_a <= G_c:
//   linear (the default): the straight line through a and b;
//   cubic (Interpolation::kCubic, per channel): the cubic Hermite through a and b whose slopes are
//   those of the parabolas through (a's predecessor, a, b) and (a, b, b's successor): Catmull-Rom
//   on a uniform grid, exact on quadratics. Where a neighbour is missing or beyond a gap, that
//   end's slope is the secant's (with both, the line). Why: linear interpolation attenuates a
//   signal between frames, 1 - u (1 - u) (w T)^2 / 2 at a fraction u of the frame period T: a
//   50 Hz message read half a period off the grid loses 0.13 % of a 1 Hz sine steer, which biased
//   a yaw inertia by +0.18 % on noise-free data; the cubic's loss is of order (w T)^4. A channel
//   that steps (a gear, a status) keeps linear: a cubic overshoots a step by up to 7 %.
// A cubic channel decides a row one frame later: it waits for b's successor (its slope) until the
// channel is stale by the frames' own clock (not the live loop's idle clock, which could run
// ahead of a frame in flight and make a live row differ from its replay) or the latency passes. Otherwise the channel is missing at t_k: nothing is ever interpolated across
// a gap, and nothing is extrapolated past the last sample or before the first. A row is valid
// when every channel has a value; an invalid row carries zeros (ingest::Chunk's convention).
//   G_c = the mapping's max_gap if the profile sets one, else max_gap_periods x the signal's own
//   period, estimated as the median of its last intervals (kPeriodWindow) including the one
//   being judged. A median ignores the gap it judges (among >= kMinIntervals normal ones) and
//   follows a real change of rate; it needs kMinIntervals intervals, so a channel's first
//   intervals are not interpolated. The estimate is fixed when b arrives, so the result depends
//   only on the samples, not on how they were batched. Event-driven (send-on-change) signals do
//   not fit this rule: give them max_gap.
//
// Times are seconds within [0, kMaxTimestamp] (signal_mapper.hpp drops frames outside it), where
// a double resolves every grid period.
//
// Streaming and latency: the clock is the newest timestamp seen (push or advance_clock, which
// the pipeline calls for every frame, mapped or not). Row k is emitted, in order, as soon as
// every channel has decided it: it has a sample at or after t_k, or the clock has reached t_k and
// the channel is stale (the clock is past its last sample + max_gap_periods x the longest
// interval of its window, beyond which the rule above cannot bridge whatever comes next) or the
// clock is past t_k + max_latency. So a row is emitted at most max_latency (source clock)
// after its time even if a channel falls silent. finish() emits the rows up to the last time
// every channel with data has reached, then stops.
//
// Samples of a channel that do not advance its time (duplicate or backwards timestamps) are
// dropped and counted. Memory per channel is bounded by the samples within the latency window.
//
// Time jumps (source_clock.hpp). The source clock of push and advance_clock is cut into pieces
// by SourceClock with config.jumps: a time more than jumps.forward after the newest one, or more
// than jumps.backward before it, ends the grid piece. Ending a piece emits what finish() emits
// (the rows every channel with data has reached), then one invalid row if the last row emitted
// was valid, so that a consumer's valid segment ends there (the server never filters across
// it); every channel's history is dropped (as at the start of a run). The next sample starts the
// new piece: its first row lies at that sample's time. No row is emitted for the time between,
// so the rows a jump costs are bounded (at most one, plus the rows of a latency window), whatever
// its size; the grid index counts rows, and across a jump it is no longer (time - origin) x rate.
// idle(time) is the live loop's clock: once it is more than jumps.forward past the newest
// sample's or frame's time, the piece ends the same way, and nothing more is emitted until data
// returns (a bus silent for hours costs at most jumps.forward of invalid rows).
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "dynid/car/source_clock.hpp"

namespace dynid::car {

enum class Interpolation { kLinear, kCubic };

struct ResamplerConfig {
  double rate_hz = 0.0;
  std::size_t channels = 0;
  double max_gap_periods = 2.5;
  std::vector<std::optional<double>> max_gap;  ///< per channel (seconds), or empty
  std::vector<Interpolation> interpolation;    ///< per channel, or empty (all linear)
  double max_latency = 1.0;                    ///< seconds of source clock
  std::optional<double> origin;                ///< grid time 0; unset: the first sample's time
  TimeJumpLimits jumps;                        ///< where the source clock jumps (see above)
};

struct ResamplerStats {
  std::uint64_t samples = 0;
  std::uint64_t out_of_order = 0;  ///< dropped: time not after the channel's previous sample
  std::uint64_t rows = 0;
  std::uint64_t invalid_rows = 0;
  std::vector<std::uint64_t> missing_by_channel;  ///< rows where this channel had no value
  std::vector<std::uint64_t> samples_by_channel;  ///< samples given, per channel
  std::uint64_t pieces_ended = 0;  ///< grid pieces ended by a time jump or a silence
};

class Resampler {
 public:
  static constexpr std::size_t kPeriodWindow = 15;
  static constexpr std::size_t kMinIntervals = 3;

  /// Receives every row in grid order: index k, one value per channel, valid flag.
  using RowSink = std::function<void(std::uint64_t, std::span<const double>, bool)>;

  /// Throws InputError for a non-positive rate, no channel, max_gap_periods < 1, a
  /// non-positive max_gap or max_latency, a max_gap or interpolation list of the wrong length, or jump limits
  /// that are not positive and finite.
  Resampler(ResamplerConfig config, RowSink sink);

  void push(std::size_t channel, double time, double value);
  void advance_clock(double time);
  /// A live loop's clock without a frame: rows leave within the latency; a silence longer than
  /// jumps.forward ends the piece (see Time jumps).
  void idle(double time);
  void finish();

  /// Source time of grid index 0 (of the first piece; later pieces start elsewhere).
  double origin() const { return first_origin_.value_or(0.0); }
  bool started() const { return origin_.has_value(); }
  std::uint64_t next_row() const { return next_row_; }
  const ResamplerStats& stats() const { return stats_; }

 private:
  struct Sample {
    double time;
    double value;
    bool bridgeable;  // the interval ending here is short enough to interpolate across
  };
  struct Channel {
    std::deque<Sample> samples;
    std::array<double, kPeriodWindow> intervals{};
    std::size_t interval_count = 0;
  };

  double row_time(std::uint64_t k) const;
  void observe(double time);
  void start_piece(double time);
  void end_piece();
  void emit_reached();
  void deliver(bool valid);
  double judge_interval(std::size_t channel, Channel& c, double interval);
  double stale_after(std::size_t channel, const Channel& c) const;
  bool decided(std::size_t channel, double t) const;
  std::optional<double> value_at(std::size_t channel, double t) const;
  void emit_ready();
  void emit_row(double t);
  static void prune(Channel& c, double t);

  ResamplerConfig config_;
  RowSink sink_;
  std::vector<Channel> channels_;
  std::optional<double> origin_;        // source time of row piece_first_row_; unset between pieces
  std::optional<double> first_origin_;  // of the first piece
  std::uint64_t piece_first_row_ = 0;
  SourceClock source_clock_;
  bool last_valid_ = false;  // of the last row emitted
  double clock_ = -std::numeric_limits<double>::infinity();       // newest time seen, idle included
  double frame_clock_ = -std::numeric_limits<double>::infinity();  // newest frame time seen
  std::uint64_t next_row_ = 0;
  std::vector<double> row_;
  ResamplerStats stats_;
};

}  // namespace dynid::car
