#pragma once
// The second car's sensors and CAN bus: each catalogue channel of the truth is measured by a
// sensor with its own white-noise level (at its message's rate), delayed, scaled or misaligned
// when a family says so, and sent in the messages of bench/trace/benchcar.dbc at their cycle
// times (GenMsgCycleTime), encoded with the product's DBC encoder (can/encoder.hpp) into a
// candump log. The noise levels are this car's, not the reference simulator's.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <dynid/can/dbc.hpp>

#include "perturbation.hpp"
#include "truth.hpp"

namespace dynid::benchcar {

struct SensorSpec {
  std::string channel;   ///< catalogue channel measured (SI)
  std::string message;   ///< DBC message
  std::vector<std::string> signals;  ///< the SI value is split evenly over these (their sum)
  double to_dbc = 1.0;   ///< SI -> DBC physical unit
  double noise = 0.0;    ///< white-noise std of the channel at its message rate, SI
  /// Its noise from a stream of its own: a sensor added to the set leaves the others' noise, and
  /// so the benchmark's runs per seed, as they were.
  bool own_stream = false;
};

/// The sensor set of benchcar.toml (one entry per channel of the profile).
const std::vector<SensorSpec>& sensor_set();

struct BusOptions {
  double noise_scale = 1.0;  ///< 0: a noise-free run (quantization and float rounding only)
  std::uint64_t seed = 1;
  /// Every noise draw of `seed` with its sign flipped: the second run of an antithetic pair
  /// (bench/coverage --antithetic), whose error's odd terms in the noise cancel the first's.
  bool mirrored = false;
};

/// Writes the run's CAN log (candump -l format, interface "can1") to `path`. Returns the
/// number of frames. Throws InputError when a value does not fit its signal.
std::size_t write_can_log(const std::filesystem::path& path, const can::Database& dbc, const Truth& truth,
                          const Perturbation& perturbation, const BusOptions& options);

}  // namespace dynid::benchcar
