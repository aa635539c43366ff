#pragma once
// Internal: naming and units of the channels the server derives (d_<name>, docs/CHANNELS.md).
#include <string>

namespace dynid::ingest::detail {

/// The unit of d_<name>: <name>'s per second (m/s -> m/s^2, m -> m/s).
inline std::string derivative_unit(const std::string& unit) {
  const bool per_second = unit.size() >= 2 && unit.compare(unit.size() - 2, 2, "/s") == 0;
  return per_second ? unit + "^2" : unit + "/s";
}

}  // namespace dynid::ingest::detail
