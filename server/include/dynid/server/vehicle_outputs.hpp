#pragma once
// VehicleOutputs: the per-vehicle writers of one worker (ChunkAck and Estimate in the
// vehicle's partition "vehicle/<id>", created on first use), and RevisionClock, which numbers
// estimate publications.
//
// A vehicle id that cannot name a partition (empty, too long, a wildcard) has no writers:
// writers() throws InputError, and the server can only log what it would have said.
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "dynid/dds/writer.hpp"
#include "dynid.h"

namespace dynid::server {

/// Estimate revisions: increasing across publications and across restarts of the server
/// (seeded from the wall clock in microseconds; each call returns max(last + 1, now)).
class RevisionClock {
 public:
  std::uint64_t next();

 private:
  std::atomic<std::uint64_t> last_{0};
};

class VehicleOutputs {
 public:
  struct Writers {
    Writers(const dds::Participant& participant, const std::string& partition)
        : ack(participant, {partition}), estimate(participant, {partition}) {}
    dds::Writer<dynid_wire_ChunkAck> ack;
    dds::Writer<dynid_wire_Estimate> estimate;
  };

  Writers& writers(const dds::Participant& participant, const std::string& vehicle);

 private:
  std::map<std::string, std::unique_ptr<Writers>> writers_;
};

}  // namespace dynid::server
