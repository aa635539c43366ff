#pragma once
// DroppedSamples: the channel samples a run leaves out where they enter because no row may carry
// them: NaN or infinite (a float signal carrying garbage), or larger in magnitude than any chunk
// may hold (ingest::ChunkLimits::max_abs_value: a sensor fault, a bit error the CRC missed, a
// float signal read as 1e20). The server refuses a chunk holding such a value, and the car would
// resend that chunk, and every one after it, for ever: one sample would stall the run. Left out,
// it is a missing sample to the resampler (interpolated across, or a gap by the channel's
// max_gap rule), the rest of the run is delivered, and the report names each channel with its
// count and its first such sample.
//
// Contract: keep() is true for a value a chunk can carry; otherwise it counts the sample under
// its channel (the first one's time and value kept) and returns false.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace dynid::car {

struct VehicleProfile;

class DroppedSamples {
 public:
  struct Channel {
    std::uint64_t count = 0;
    double first_time = 0.0;   ///< seconds, on the clock the times were given on
    double first_value = 0.0;  ///< as decoded, SI
  };

  /// Whether a chunk can carry `value`.
  static bool carriable(double value);

  bool keep(std::size_t channel, double time, double value);
  /// One line per channel: "channel 'vx': 1 sample left out (the first 2.5e+19, beyond the
  /// 1e+15 a chunk may carry, at 12.340 s of the bus's clock); ...". `where` names the clock the
  /// times are on ("the bus": auxiliary samples are put on the bus's clock before they enter).
  std::vector<std::string> report(const VehicleProfile& profile, const std::string& where) const;

 private:
  std::map<std::size_t, Channel> by_channel_;
};

}  // namespace dynid::car
