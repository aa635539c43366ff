#pragma once
// SourceClock: the clock of a frame source, cut into pieces where it jumps. A candump log can
// jump (recorded across a clock change, edited, two logs concatenated, one corrupted
// timestamp); a live bus can fall silent for hours. Neither is data: nothing is synthesised for
// the time between, and a jump backwards does not discard what follows.
//
// Rule: the first time starts the first piece. A later time more than limits.forward seconds
// after the newest time of the current piece, or more than limits.backward seconds before it,
// is a jump and starts a new piece at that time; any other time continues the piece (a small
// step back is a frame slightly out of order). elapsed() is the source time the pieces cover,
// the sum of (newest - first) over pieces: a jump adds nothing to it, whatever its size.
//
// The Resampler ends its grid piece at a jump (resampler.hpp), and the replay paces on elapsed()
// (replay.hpp), so a jump of 1e9 s neither fills the grid nor makes the replay wait.
#include <cstdint>

namespace dynid::car {

struct TimeJumpLimits {
  double forward = 10.0;  ///< seconds; the profile's [grid] max_time_jump
  double backward = 1.0;  ///< seconds; the resampler's latency: rows that old are already out
};

class SourceClock {
 public:
  /// Throws InputError unless both limits are positive and finite.
  explicit SourceClock(TimeJumpLimits limits = {});

  /// Takes the next time (finite); true when it starts a new piece after a jump (false for the
  /// very first time, which starts the first piece).
  bool step(double time);
  /// True when the source has been silent past the forward limit at `time` (a live loop's
  /// clock): the piece is over, whatever comes next.
  bool silent_at(double time) const { return started_ && time > newest_ + limits_.forward; }

  bool started() const { return started_; }
  double elapsed() const { return covered_ + (started_ ? newest_ - first_ : 0.0); }
  std::uint64_t jumps() const { return jumps_; }
  const TimeJumpLimits& limits() const { return limits_; }

 private:
  TimeJumpLimits limits_;
  bool started_ = false;
  double first_ = 0.0;    // first time of the current piece
  double newest_ = 0.0;   // newest time of the current piece
  double covered_ = 0.0;  // elapsed() of the pieces before
  std::uint64_t jumps_ = 0;
};

}  // namespace dynid::car
