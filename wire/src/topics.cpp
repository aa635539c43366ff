#include "dynid/dds/topics.hpp"

#include <dynid/input/ids.hpp>

#include "dynid/error.hpp"

namespace dynid::dds {

static_assert(input::kMaxIdLength == dynid_wire_kIdLength, "the id rule's bound is the wire's");

std::string vehicle_partition(std::string_view vehicle) {
  try {
    input::check_vehicle_id(vehicle);
  } catch (const InputError& e) {
    throw InputError(std::string("partition: ") + e.what());
  }
  return std::string(kVehiclePartitionPrefix) + std::string(vehicle);
}

}  // namespace dynid::dds
