#include "dynid/dds/sender_partition.hpp"

#include <spdlog/spdlog.h>

#include <dynid/input/ids.hpp>

#include <algorithm>
#include <cstring>

#include "dynid/dds/topics.hpp"

namespace dynid::dds {

namespace {

bool has_wildcard(const std::vector<std::string>& partitions) {
  return std::any_of(partitions.begin(), partitions.end(),
                     [](const std::string& p) { return p.find_first_of("*?") != std::string::npos; });
}

std::string joined(const std::vector<std::string>& partitions) {
  std::string out;
  for (const auto& p : partitions) out += (out.empty() ? "\"" : ", \"") + p + "\"";
  return out.empty() ? "the default partition" : out;
}

}  // namespace

SenderPartitionGuard::SenderPartitionGuard(dds_entity_t reader,
                                           const std::vector<std::string>& reader_partitions)
    : reader_(reader), active_(has_wildcard(reader_partitions)) {}

SenderPartitionGuard::WriterPartitions SenderPartitionGuard::look_up(
    dds_instance_handle_t publication) const {
  WriterPartitions found;
  dds_builtintopic_endpoint_t* endpoint = dds_get_matched_publication_data(reader_, publication);
  if (!endpoint) return found;
  found.matched = true;
  uint32_t count = 0;
  char** names = nullptr;
  if (endpoint->qos && dds_qget_partition(endpoint->qos, &count, &names)) {
    for (uint32_t k = 0; k < count; ++k) {
      found.partitions.emplace_back(names[k]);
      dds_free(names[k]);
    }
    dds_free(names);
  }
  dds_builtintopic_free_endpoint(endpoint);
  return found;
}

SenderPartitionGuard::WriterPartitions& SenderPartitionGuard::writer(dds_instance_handle_t publication) {
  if (const auto it = writers_.find(publication); it != writers_.end()) return it->second;
  WriterPartitions found = look_up(publication);
  if (!found.matched) return unmatched_ = found;  // not cached: nothing to remember of it
  return writers_.emplace(publication, std::move(found)).first->second;
}

bool SenderPartitionGuard::admits(dds_instance_handle_t publication, const char* vehicle,
                                  std::size_t capacity) {
  if (!active_) return true;
  const std::size_t length = strnlen(vehicle, capacity);
  if (length == 0 || length == capacity) return true;  // malformed: from_wire reports it
  const std::string own = std::string(kVehiclePartitionPrefix) + std::string(vehicle, length);
  WriterPartitions& w = writer(publication);
  if (w.matched && std::find(w.partitions.begin(), w.partitions.end(), own) != w.partitions.end())
    return true;
  ++refused_;
  if (!w.reported) {
    // Escaped: both the key and the partitions come from the network.
    spdlog::warn("sample keyed vehicle '{}' refused: its writer {} {}", input::printable(std::string(vehicle, length)),
                 publication, w.matched ? "wrote in " + input::printable(joined(w.partitions)) + ", not \"" +
                                              input::printable(own) + "\""
                                        : "is no longer matched, its partition cannot be checked");
    w.reported = true;
  }
  return false;
}

}  // namespace dynid::dds
