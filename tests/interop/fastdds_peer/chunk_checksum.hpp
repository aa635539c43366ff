#pragma once
// The checksum a dynid/Chunk carries (docs/INTEROP.md, "Chunk checksum"): CRC-32 (zlib) of the
// chunk's canonical little-endian encoding, "DYNIDCHK", u16 version 1, vehicle and run (u32
// length + bytes), u64 sequence_number, u64 first_sample_index, u64 rows, u64 channels, the
// samples row by row as binary64, u64 flag count and the flags (one byte each). The server
// refuses a chunk whose checksum differs (a rejection in its ChunkAck).
#include <cstdint>

#include "dynid.h"  // fastddsgen's C++ of idl/dynid.idl

namespace peer {

std::uint32_t chunk_checksum(const dynid::wire::Chunk& chunk);

}  // namespace peer
