#pragma once
// ChunkReceipt: the server's acknowledgement of one run's chunks (wire type ChunkAck).
//
// Every chunk with sequence <= highest_contiguous is stored durably (highest_contiguous = -1:
// none yet), so the car may drop it from its spool. `rejections` lists chunks that were
// refused and why (they changed no state); the wire carries the most recent
// dynid_wire_kMaxRejections of them, reasons cut at dynid_wire_kReasonLength characters.
#include <cstdint>
#include <string>
#include <vector>

namespace dynid::dds {

struct ChunkRejection {
  std::uint64_t sequence = 0;
  std::string reason;
};

struct ChunkReceipt {
  std::string vehicle;
  std::string run;
  std::int64_t highest_contiguous = -1;
  std::vector<ChunkRejection> rejections;
};

}  // namespace dynid::dds
