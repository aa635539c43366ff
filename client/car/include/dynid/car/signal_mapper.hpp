#pragma once
// SignalMapper: one CAN frame -> the channel samples it carries, through the profile's DBC and
// channel mappings (unit conversion and transforms happen here, where signals enter).
//
// Contract: map() never throws for bad input. It classifies each frame (FrameOutcome) and counts
// it in stats(): frames from interfaces the profile does not listen to, unknown ids, remote
// frames and payloads too short for the message are counted and produce no sample; a frame
// whose channel value no chunk may carry (NaN/Inf, or beyond the chunk limit: dropped_samples.hpp)
// produces no sample for that channel and is counted as non_finite or out_of_range, and under
// its channel in dropped(). A frame whose timestamp is not usable_time() (negative, or
// past kMaxTimestamp) is counted as bad_time and produces nothing: on such a clock a grid period
// is below the resolution of a double (at 1e299 s, t + 0.01 == t), so the resampler could not
// tell one row from the next. A constant channel of the profile (ChannelMapping::constant) gets a
// sample at every frame that carries a channel of the profile, so it moves neither the run's
// first sample nor its grid. The profile must outlive the mapper.
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <dynid/can/decoder.hpp>

#include "dynid/car/dropped_samples.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {

struct ChannelSample {
  std::size_t channel = 0;  ///< index in VehicleProfile::channels
  double time = 0.0;        ///< the frame's timestamp, seconds
  double value = 0.0;       ///< SI
};

enum class FrameOutcome { Mapped, Unmapped, OtherInterface, UnknownId, RemoteFrame, ShortPayload, BadTime };

/// Epoch seconds of the year 2286: a double still resolves 2 us there (a 10 kHz grid's period
/// is 50 of its steps). Logs with a relative clock (from 0) are within it too.
inline constexpr double kMaxTimestamp = 1e10;
inline bool usable_time(double seconds) { return seconds >= 0.0 && seconds <= kMaxTimestamp; }

struct MapStats {
  std::uint64_t frames = 0;
  std::uint64_t mapped = 0;           ///< decoded and used by at least one channel
  std::uint64_t unmapped = 0;         ///< decoded, but no channel uses the message
  std::uint64_t other_interface = 0;  ///< ignored: not a bus the profile listens to
  std::uint64_t unknown_id = 0;
  std::uint64_t remote = 0;
  std::uint64_t short_payload = 0;
  std::uint64_t non_finite = 0;       ///< channel values dropped because NaN/Inf
  std::uint64_t out_of_range = 0;     ///< channel values dropped: beyond what a chunk may carry
  std::uint64_t bad_time = 0;         ///< frames dropped: timestamp not usable_time()
  std::uint64_t decoded() const { return mapped + unmapped; }
};

class SignalMapper {
 public:
  explicit SignalMapper(const VehicleProfile& profile);

  /// Appends the frame's channel samples to `out` (not cleared).
  FrameOutcome map(const can::Frame& frame, std::vector<ChannelSample>& out);
  const MapStats& stats() const { return stats_; }
  const DroppedSamples& dropped() const { return dropped_; }

 private:
  const VehicleProfile& profile_;
  can::Decoder decoder_;
  std::unordered_map<const can::Message*, std::vector<std::size_t>> channels_of_;
  std::vector<std::size_t> constants_;  // the profile's constant channels: a sample at every frame
  std::vector<can::DecodedSignal> decoded_;
  std::vector<double> physical_;
  MapStats stats_;
  DroppedSamples dropped_;
};

}  // namespace dynid::car
