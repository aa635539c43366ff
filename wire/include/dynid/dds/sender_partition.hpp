#pragma once
// SenderPartitionGuard: binds a sample's vehicle key to the partition its writer wrote in, on a
// reader that gathers many vehicles' partitions through a wildcard (the server's "vehicle/*").
//
// Why: DDS Security grants a car its own partition "vehicle/<id>" only (docs/SECURITY.md), but
// access control sees partitions, not keys. Without this check a car could write, in its own
// partition, an announcement or chunk keyed with another vehicle's id, and a wildcard reader
// would take it as that vehicle's data.
//
// Contract:
// - Active only when the reader's partitions hold a wildcard ('*' or '?'); a reader of one
//   vehicle's partition only ever matches writers of that partition and admits everything.
// - admits(publication, vehicle) is true when the matched writer `publication` (the sample
//   info's publication_handle) has "vehicle/<vehicle>" among its partitions. A writer that is
//   no longer matched (gone before its sample was taken) cannot be checked: refused. A vehicle
//   field that is not a terminated string is admitted here: from_wire() refuses it with the
//   reason (conversions.hpp), which is where malformed samples are reported.
// - Every refusal is counted (refused()) and logged at warning level (once per matched writer;
//   every time for writers no longer matched), naming the writer's partitions and the key; the
//   sample is dropped and changes no state.
// - A writer's partitions are looked up once (dds_get_matched_publication_data) and cached;
//   Cyclone never reuses an instance handle.
#include <dds/dds.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace dynid::dds {

class SenderPartitionGuard {
 public:
  SenderPartitionGuard(dds_entity_t reader, const std::vector<std::string>& reader_partitions);

  bool active() const { return active_; }
  /// `vehicle` points at the sample's fixed-size id field of `capacity` bytes.
  bool admits(dds_instance_handle_t publication, const char* vehicle, std::size_t capacity);
  std::uint64_t refused() const { return refused_; }

 private:
  struct WriterPartitions {
    bool matched = false;  // false: not (or no longer) a matched writer
    std::vector<std::string> partitions;
    bool reported = false;
  };
  WriterPartitions look_up(dds_instance_handle_t publication) const;
  WriterPartitions& writer(dds_instance_handle_t publication);

  dds_entity_t reader_;
  bool active_;
  std::map<dds_instance_handle_t, WriterPartitions> writers_;  // matched writers seen
  WriterPartitions unmatched_;  // the last writer found no longer matched
  std::uint64_t refused_ = 0;
};

}  // namespace dynid::dds
