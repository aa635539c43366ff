#include "dynid/server/vehicle_outputs.hpp"

#include <algorithm>
#include <chrono>

#include "dynid/dds/topics.hpp"

namespace dynid::server {

std::uint64_t RevisionClock::next() {
  const auto now = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(
          std::chrono::system_clock::now().time_since_epoch())
          .count());
  std::uint64_t last = last_.load();
  std::uint64_t next = 0;
  do {
    next = std::max(last + 1, now);
  } while (!last_.compare_exchange_weak(last, next));
  return next;
}

VehicleOutputs::Writers& VehicleOutputs::writers(const dds::Participant& participant,
                                                 const std::string& vehicle) {
  auto it = writers_.find(vehicle);
  if (it == writers_.end()) {
    const std::string partition = dds::vehicle_partition(vehicle);  // InputError if unusable
    it = writers_.emplace(vehicle, std::make_unique<Writers>(participant, partition)).first;
  }
  return *it->second;
}

}  // namespace dynid::server
