#pragma once
// Conversions between the wire samples (idl/dynid.idl) and the transport-neutral structs.
//
// to_wire(): builds an owned wire sample. Throws InputError naming the field when a value does
// not fit the wire bounds (an id or name too long, too many channels, rows x channels over
// dynid_wire_kMaxChunkValues, a valid-flag count that is not the row count, ...). Free text
// that is only read by people (rejection reasons, relations, reply errors) is cut to its bound
// instead; the ack keeps the most recent rejections.
//
// from_wire(): validates the *shape* of a received sample and copies it out. Throws InputError
// naming the sample (e.g. "Chunk proto-17/run-3#12") and the reason: a string without its
// terminator within its bound, a sequence longer than its bound or with a null buffer,
// rows x channels != data length, valid-flag count != rows, zero rows or channels, duplicate
// constant names, an unknown enum value. It never reads past a buffer. The *meaning* (finite
// values, checksum, channels against the announcement) is the ingest contract's:
// RunAnnouncement::validate() and validate_chunk(), which the server applies next.
#include "dynid.h"
#include "dynid/dds/chunk_receipt.hpp"
#include "dynid/dds/estimate_table.hpp"
#include "dynid/dds/request.hpp"
#include "dynid/dds/sample.hpp"
#include "dynid/ingest/chunk.hpp"
#include "dynid/error.hpp"
#include "dynid/ingest/run_announcement.hpp"

namespace dynid::dds {

Sample<dynid_wire_RunAnnouncement> to_wire(const ingest::RunAnnouncement& announcement);
ingest::RunAnnouncement from_wire(const dynid_wire_RunAnnouncement& sample);

Sample<dynid_wire_Chunk> to_wire(const ingest::Chunk& chunk);
ingest::Chunk from_wire(const dynid_wire_Chunk& sample);

Sample<dynid_wire_ChunkAck> to_wire(const ChunkReceipt& receipt);
ChunkReceipt from_wire(const dynid_wire_ChunkAck& sample);

Sample<dynid_wire_Estimate> to_wire(const EstimateTable& table);
EstimateTable from_wire(const dynid_wire_Estimate& sample);

Sample<dynid_wire_Request> to_wire(const Request& request);
Request from_wire(const dynid_wire_Request& sample);

Sample<dynid_wire_Reply> to_wire(const Reply& reply);
Reply from_wire(const dynid_wire_Reply& sample);

}  // namespace dynid::dds
