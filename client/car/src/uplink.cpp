#include "dynid/car/uplink.hpp"

#include <dynid/dds/conversions.hpp>
#include <dynid/dds/error.hpp>
#include <dynid/dds/topics.hpp>
#include <dynid/error.hpp>

namespace dynid::car {

Uplink::Uplink(const dds::Participant& participant, const std::string& vehicle)
    : vehicle_(vehicle),
      announcements_(participant, {dds::vehicle_partition(vehicle)}),
      chunks_(participant, {dds::vehicle_partition(vehicle)}),
      acks_(participant, {dds::vehicle_partition(vehicle)}) {}

void Uplink::announce(const ingest::RunAnnouncement& announcement) {
  const auto sample = dds::to_wire(announcement);
  // A state topic never blocks (keep-last 1); false would mean Cyclone itself timed out.
  if (!announcements_.write(sample.data))
    throw dds::DdsError("dds_write(RunAnnouncement " + announcement.run + ")", DDS_RETCODE_TIMEOUT);
}

bool Uplink::send(const ingest::Chunk& chunk) {
  const auto sample = dds::to_wire(chunk);
  return chunks_.write(sample.data);
}

std::vector<dds::ChunkReceipt> Uplink::receipts(std::chrono::milliseconds wait) {
  std::vector<dds::ChunkReceipt> out;
  auto samples = wait.count() > 0 ? acks_.wait_take(wait) : acks_.take();
  for (const auto& sample : samples) {
    try {
      auto receipt = dds::from_wire(sample.data);
      if (receipt.vehicle != vehicle_)  // the partition is ours; a stray key is bad input
        throw InputError("ChunkAck for vehicle '" + receipt.vehicle + "' in the partition of '" + vehicle_ + "'");
      out.push_back(std::move(receipt));
    } catch (const InputError& e) {
      ++bad_receipts_;
      last_bad_receipt_ = e.what();
    }
  }
  return out;
}

std::uint32_t Uplink::readers_matched_total() const {
  dds_publication_matched_status_t status;
  dds::check(dds_get_publication_matched_status(chunks_.handle(), &status), "publication matched status");
  return status.total_count;
}

}  // namespace dynid::car
