#include "dynid/dds/topics.hpp"

#include "dynid/error.hpp"

namespace dynid::dds {

std::string vehicle_partition(std::string_view vehicle) {
  const std::string quoted = "vehicle id '" + std::string(vehicle) + "'";
  if (vehicle.empty()) throw InputError("partition: empty vehicle id");
  if (vehicle.size() > dynid_wire_kIdLength)
    throw InputError("partition: " + quoted + " is longer than " +
                     std::to_string(dynid_wire_kIdLength) + " characters");
  if (vehicle.find_first_of("*?\\") != std::string_view::npos)
    throw InputError("partition: " + quoted +
                     " holds a wildcard ('*', '?') or backslash: it would match other vehicles");
  return std::string(kVehiclePartitionPrefix) + std::string(vehicle);
}

}  // namespace dynid::dds
