#pragma once
// Uplink: the car's DDS endpoints for one vehicle, in its partition "vehicle/<id>": the run
// announcement writer, the chunk writer and the acknowledgement (ChunkAck) reader. It only
// moves samples; what to send when is Delivery's job (delivery.hpp).
//
// Contract:
// - announce() publishes a run announcement (transient-local, so a server that starts later
//   still gets it). send() publishes one chunk and returns false when the server's queue stayed
//   full for the chunk QoS's max_blocking_time (the chunk stays in the spool; try later). A
//   value the wire cannot carry throws InputError (to_wire); a DDS failure throws DdsError.
// - receipts() waits up to `wait` for acknowledgements and returns the valid ones. The reader
//   is transient-local: the first call after start-up also returns the server's latest receipt
//   of every run of the vehicle. A malformed receipt is counted (bad_receipts()) and its reason
//   kept (last_bad_receipt()), never returned.
// - readers_matched_total() counts the chunk readers (servers) that ever matched the chunk
//   writer: when it grows, a server (re)appeared and missed whatever was sent before (chunks
//   are volatile), so Delivery resends what is unacknowledged at once instead of waiting for
//   the acknowledgement timeout.
// - The Participant must outlive the Uplink.
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <dynid/dds/chunk_receipt.hpp>
#include <dynid/dds/participant.hpp>
#include <dynid/dds/reader.hpp>
#include <dynid/dds/writer.hpp>
#include <dynid/ingest/chunk.hpp>
#include <dynid/ingest/run_announcement.hpp>

namespace dynid::car {

class Uplink {
 public:
  Uplink(const dds::Participant& participant, const std::string& vehicle);

  void announce(const ingest::RunAnnouncement& announcement);
  bool send(const ingest::Chunk& chunk);
  std::vector<dds::ChunkReceipt> receipts(std::chrono::milliseconds wait);
  std::uint32_t readers_matched_total() const;

  std::uint64_t bad_receipts() const { return bad_receipts_; }
  const std::string& last_bad_receipt() const { return last_bad_receipt_; }
  const std::string& vehicle() const { return vehicle_; }

 private:
  std::string vehicle_;
  dds::Writer<dynid_wire_RunAnnouncement> announcements_;
  dds::Writer<dynid_wire_Chunk> chunks_;
  dds::Reader<dynid_wire_ChunkAck> acks_;
  std::uint64_t bad_receipts_ = 0;
  std::string last_bad_receipt_;
};

}  // namespace dynid::car
