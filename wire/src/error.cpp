#include "dynid/dds/error.hpp"

namespace dynid::dds {

DdsError::DdsError(const std::string& call, dds_return_t code)
    : std::runtime_error(call + ": " + dds_strretcode(code)), code_(code) {}

dds_return_t check(dds_return_t result, const std::string& call) {
  if (result < 0) throw DdsError(call, result);
  return result;
}

}  // namespace dynid::dds
