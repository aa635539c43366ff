#pragma once
// Chunk: a block of consecutive samples of one run on its uniform grid, as the car streams it.
//
// Rows are samples, columns follow RunAnnouncement::channels. `valid[k] == 0` marks a sample in
// a gap (a signal missing or stale at that grid time: the car-side resampler never interpolates
// across a gap); the values of an invalid row are ignored but must still be finite (0 is used).
// Sequence numbers start at 0 and increase by one per chunk of a run; `first_sample_index` is
// the grid index of row 0 (time = first_sample_index / sample_rate from the run's start, except
// that a jump of the car's clock costs no index: the car ends its grid piece with an invalid row
// and goes on at the next index, client resampler.hpp "Time jumps"), which makes chunks
// self-locating and lets the server detect missing or overlapping samples.
//
// The checksum is CRC-32 (zlib) over a canonical little-endian encoding of every field but the
// checksum itself: it is what the server checks before storing, and what it stores.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/ingest/run_announcement.hpp"

namespace dynid::ingest {

/// Limits on what a single chunk may hold ("absurd sizes" are rejected, not allocated).
struct ChunkLimits {
  Eigen::Index max_rows = 100000;
  Eigen::Index max_channels = 1024;
  /// Largest |value| accepted: nothing a vehicle channel in SI reaches (pressures ~1e7 Pa),
  /// and far enough from overflow that squares and sums in the accumulators stay finite.
  double max_abs_value = 1e15;

  bool operator==(const ChunkLimits&) const = default;
};

struct Chunk {
  std::string vehicle;
  std::string run;
  std::uint64_t sequence = 0;
  std::uint64_t first_sample_index = 0;
  Eigen::MatrixXd samples;          ///< rows x channels
  std::vector<std::uint8_t> valid;  ///< one flag per row (1 valid, 0 gap)
  std::uint32_t checksum = 0;

  /// CRC-32 of the canonical encoding (everything but `checksum`).
  std::uint32_t compute_checksum() const;
  /// Sets `checksum` from the content.
  void seal() { checksum = compute_checksum(); }
};

/// Checks a chunk against its run: ids match, dimensions (columns = announced channels, rows
/// within limits and > 0, one valid flag per row, flags 0/1), checksum right, every value finite
/// and within limits.max_abs_value. Throws InputError naming the chunk (vehicle/run#sequence)
/// and the reason (for a bad value: row, channel name). Sequence order is the caller's (the
/// ledger's) concern.
///
/// Encoding (version 1, little-endian): "DYNIDCHK", u16 version, vehicle and run (u32 length +
/// bytes), u64 sequence, u64 first_sample_index, u64 rows, u64 columns, the samples row by row
/// as binary64, u64 flag count and the flags (one byte each), then the u32 checksum. The checksum
/// is the CRC-32 of everything before it, so compute_checksum() is defined by this layout.
void validate_chunk(const Chunk& chunk, const RunAnnouncement& run, const ChunkLimits& limits = {});

/// validate_chunk, returning encode_chunk(chunk): checking the checksum encodes the chunk, so a
/// caller that also stores the bytes (the server) gets them without encoding it a second time.
std::string validate_and_encode(const Chunk& chunk, const RunAnnouncement& run,
                                const ChunkLimits& limits = {});

/// Exact binary encoding of a chunk (for the store and the spool) and its inverse, which
/// throws InputError on truncated or corrupted input (the checksum is verified).
std::string encode_chunk(const Chunk& chunk);
Chunk decode_chunk(std::string_view bytes);

}  // namespace dynid::ingest
