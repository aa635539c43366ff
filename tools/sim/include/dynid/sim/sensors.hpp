#pragma once
// Sensor errors: white Gaussian noise and a constant offset per channel, drawn from seeded
// random streams (sample rates and quantization belong to the CAN bus, see can_bus.hpp).
//
// Contract: every channel has its own stream, seeded from the run seed and the channel's name,
// so switching an effect or adding a channel never changes another channel's noise; the same
// seed gives the same values bit for bit (on one standard library). Offsets are drawn once per
// run (N(0, offset_sigma)) and reported in the truth file. Channels whose spec is all zero
// (gear, gear_ratio, the driver's commands known exactly) pass through unchanged.
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/sim/effects.hpp"

namespace dynid::sim {

struct SensorSpec {
  double noise = 0.0;         // standard deviation, SI
  double offset_sigma = 0.0;  // standard deviation of the run's offset, SI
};

// Typical automotive / test-instrumentation grade (nehaoua §11, venture §5.2).
SensorSpec default_sensor(std::string_view channel);

class SensorBank {
 public:
  // `noise_scale` multiplies every noise level (not the offsets); `gains` (channel -> gain) scales
  // a sensor's reading of the truth.
  SensorBank(std::uint64_t seed, const Effects& effects, double noise_scale,
             const std::map<std::string, double>& gains = {});
  double measure(std::size_t channel, double true_value);
  const std::vector<double>& offsets() const { return offsets_; }

 private:
  std::vector<SensorSpec> specs_;
  std::vector<std::mt19937_64> streams_;
  std::vector<double> offsets_;
  std::vector<double> gains_;
  bool noise_ = true;
  double noise_scale_ = 1.0;
};

}  // namespace dynid::sim
