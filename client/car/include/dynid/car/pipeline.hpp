#pragma once
// CarPipeline: frames -> chunks for one run of one vehicle: SignalMapper (decode, map, convert)
// -> Resampler (uniform grid, gaps marked) -> ChunkBuilder (sequence numbers, seal). The replay
// and the live SocketCAN loop both drive it; the sink decides what happens to a chunk (the car
// stores it in the Spool before publishing it).
//
// Contract: on_frame() never throws for bad frames (they are counted in mapper_stats()). The
// clock of the grid is the frames' timestamps, cut into pieces where it jumps (no row is made up
// for the time of a jump: resampler.hpp, Time jumps), taken as the time since the run's first
// frame (of usable time) in whole microseconds: the chunks depend on the times between frames,
// not on where the log's clock starts nor on the format's resolution past a microsecond, so a
// candump, an ASC and a BLF log of the same frames cut the same chunks, bit for bit (a format may
// hold the measurement start only to the millisecond, or none before 1990: can/blf.hpp); idle() lets a live loop that timed out push the
// clock forward so rows still leave within the latency bound. finish() emits the last rows and
// the final partial chunk; nothing may be fed after it. The profile must outlive the pipeline.
//
// Auxiliary samples (auxiliary.hpp, given before the first frame) are merged on the frames'
// clock: before each frame, every auxiliary sample up to its time goes into the resampler, so
// the bus drives the grid and an auxiliary channel obeys the same gap and validity rules as a
// bus channel. Samples before the run's first frame, or after its last, are dropped and counted
// (auxiliary_stats()).
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "dynid/car/auxiliary.hpp"
#include "dynid/car/chunk_builder.hpp"
#include "dynid/car/resampler.hpp"
#include "dynid/car/signal_mapper.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {

struct AuxiliaryStats {
  std::uint64_t merged = 0;
  std::uint64_t before_bus = 0;  ///< dropped: before the run's first frame
  std::uint64_t after_bus = 0;   ///< dropped: after its last frame
  std::uint64_t out_of_range = 0;  ///< dropped: a value no chunk may carry (dropped_samples.hpp)
};

class CarPipeline {
 public:
  CarPipeline(const VehicleProfile& profile, const std::string& run, ChunkBuilder::ChunkSink sink,
              std::uint64_t first_sequence = 0);

  void on_frame(const can::Frame& frame);
  /// Samples of the run's auxiliary channels, sorted by time (RunSources::samples).
  void add_auxiliary(std::vector<AuxiliarySample> samples);
  /// More samples of a live run (live_merge.hpp), sorted by time, none before the last given
  /// nor at or before newest_frame_time(): they join those given before.
  void append_auxiliary(std::vector<AuxiliarySample> samples);
  /// Source-clock time of the newest frame taken (-inf before the first).
  double newest_frame_time() const { return first_time_ ? last_time_ : -std::numeric_limits<double>::infinity(); }
  /// Advances the grid clock to `time` (source clock) without a frame; a silence longer than
  /// the profile's max_time_jump ends the grid piece (resampler.hpp, Time jumps).
  void idle(double time);
  void finish();

  const MapStats& mapper_stats() const { return mapper_.stats(); }
  const ResamplerStats& resampler_stats() const { return resampler_.stats(); }
  std::uint64_t chunks() const { return builder_.chunks(); }
  const AuxiliaryStats& auxiliary_stats() const { return aux_stats_; }
  /// The samples left out because no chunk may carry them (dropped_samples.hpp), one line per
  /// channel of the bus and of the auxiliary sources.
  std::vector<std::string> dropped_report() const;
  /// The channels that had no value in at least 1 % of the rows (and 10 rows), most first, each
  /// with where it comes from: what made those rows invalid ("channel 'yaw_rate' had no value in
  /// 3991 of 3991 rows (no sample at all from message 'ESP_Dynamics', signal YawRate)").
  std::vector<std::string> missing_report() const;
  /// Where the frames' clock jumps (the profile's max_time_jump; the resampler's latency back).
  TimeJumpLimits time_jumps() const { return time_jumps_; }
  /// Source-clock time of grid index 0 (valid once the first sample arrived).
  double origin() const { return first_time_.value_or(0.0) + resampler_.origin(); }
  /// Source-clock time of the run's first frame (the grid's clock counts from it), if any yet.
  std::optional<double> first_time() const { return first_time_; }

 private:
  const VehicleProfile& profile_;
  TimeJumpLimits time_jumps_;
  SignalMapper mapper_;
  ChunkBuilder builder_;
  Resampler resampler_;
  std::vector<ChannelSample> samples_;
  std::optional<double> first_time_;
  double last_time_ = 0.0;  // newest frame time (source clock)
  std::vector<AuxiliarySample> aux_;
  std::size_t aux_next_ = 0;
  AuxiliaryStats aux_stats_;
  DroppedSamples aux_dropped_;

  double run_time(double source_time);
  void push_auxiliary_until(double source_time);
};

}  // namespace dynid::car
