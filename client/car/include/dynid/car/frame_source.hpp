#pragma once
// FrameSource: where the car-side pipeline gets its CAN frames. The replay reader (a candump log,
// candump_source.hpp) and the live SocketCAN reader (client/car/src/socketcan/) both implement it,
// so the mapping, resampling, chunking and spool code never knows which one feeds it.
//
// Contract:
// - next() fills `frame` and returns Frame, or returns End once the source is exhausted (a log at
//   its end, a closed socket: every later call returns End again), or Timeout when no frame came
//   within `timeout` (live sources; a log never times out). `frame` is unspecified unless Frame.
// - Frame timestamps are seconds on the source's clock. They may jump, forwards or backwards, by
//   any amount: the consumer (Resampler, source_clock.hpp) ends its grid piece at a jump, and
//   drops per-signal samples that go back less than that.
// - Input the source itself finds malformed (a bad log line, an error frame) is counted by the
//   source and never returned; bad_input() reports how many so far.
// - next() throws only for a failure of the source itself (a read error on the device), never
//   for bad data.
#include <chrono>
#include <cstdint>
#include <string>

#include <dynid/can/frame.hpp>

namespace dynid::car {

enum class NextStatus { Frame, End, Timeout };

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual NextStatus next(can::Frame& frame, std::chrono::milliseconds timeout) = 0;
  /// Malformed input seen and skipped so far (bad log lines, error frames...).
  virtual std::uint64_t bad_input() const = 0;
  /// Progress through a finite source in [0, 1]; a live source returns a negative value.
  virtual double fraction_done() const { return -1.0; }
  /// Names the source in messages ("rav4.log", "can0").
  virtual std::string name() const = 0;
};

}  // namespace dynid::car
