#pragma once
// CarPipeline: frames -> chunks for one run of one vehicle: SignalMapper (decode, map, convert)
// -> Resampler (uniform grid, gaps marked) -> ChunkBuilder (sequence numbers, seal). The replay
// and the live SocketCAN loop both drive it; the sink decides what happens to a chunk (the car
// stores it in the Spool before publishing it).
//
// Contract: on_frame() never throws for bad frames (they are counted in mapper_stats()). The
// clock of the grid is the frames' timestamps, cut into pieces where it jumps (no row is made up
// for the time of a jump: resampler.hpp, Time jumps); idle() lets a live loop that timed out push the
// clock forward so rows still leave within the latency bound. finish() emits the last rows and
// the final partial chunk; nothing may be fed after it. The profile must outlive the pipeline.
#include <cstdint>
#include <string>
#include <vector>

#include "dynid/car/chunk_builder.hpp"
#include "dynid/car/resampler.hpp"
#include "dynid/car/signal_mapper.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {

class CarPipeline {
 public:
  CarPipeline(const VehicleProfile& profile, const std::string& run, ChunkBuilder::ChunkSink sink,
              std::uint64_t first_sequence = 0);

  void on_frame(const can::Frame& frame);
  /// Advances the grid clock to `time` (source clock) without a frame; a silence longer than
  /// the profile's max_time_jump ends the grid piece (resampler.hpp, Time jumps).
  void idle(double time) { resampler_.idle(time); }
  void finish();

  const MapStats& mapper_stats() const { return mapper_.stats(); }
  const ResamplerStats& resampler_stats() const { return resampler_.stats(); }
  std::uint64_t chunks() const { return builder_.chunks(); }
  /// Where the frames' clock jumps (the profile's max_time_jump; the resampler's latency back).
  TimeJumpLimits time_jumps() const { return time_jumps_; }
  /// Source-clock time of grid index 0 (valid once the first sample arrived).
  double origin() const { return resampler_.origin(); }

 private:
  TimeJumpLimits time_jumps_;
  SignalMapper mapper_;
  ChunkBuilder builder_;
  Resampler resampler_;
  std::vector<ChannelSample> samples_;
};

}  // namespace dynid::car
