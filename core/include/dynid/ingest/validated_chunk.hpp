#pragma once
// ValidatedChunk: a chunk that passed validate_chunk against a run's announcement and limits,
// so that the next stage (RunProcessor::push) need not check it again: the CRC-32 over its
// bytes and the per-value checks are most of a chunk's validation cost.
//
// Only ValidatedChunk::validate makes one, and it holds the chunk read-only (a shared pointer
// to const: the server's decoded chunk is not copied), so a ValidatedChunk is always a chunk
// that was checked, as it was checked. It also remembers the limits it was checked under. What
// validate_chunk reads of the announcement is the vehicle and run ids and the channel count;
// a consumer compares those and the limits with its own (validated_for(), a few compares) and
// validates again on any difference, so a chunk checked for another run or under laxer limits
// is never taken as valid.
//
// It keeps the chunk's encoding (encode_chunk) too: validation computes it to check the
// checksum, and the store writes exactly those bytes. The price is the chunk's size again for
// as long as the ValidatedChunk lives (the server's: until its batch is committed and folded,
// at most kMaxBatch x (1 + kMaxInFlight) chunks per worker, run_service.cpp).
//
// Caveat: the chunk is shared, not copied; modifying it through another (non-const) pointer
// after validation voids the check. The overload taking a Chunk by value owns its copy.
#include <memory>
#include <string>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"

namespace dynid::ingest {

class ValidatedChunk {
 public:
  /// validate_chunk(*chunk, run, limits), then keeps the chunk. Throws InputError as
  /// validate_chunk does, and for a null chunk.
  static ValidatedChunk validate(std::shared_ptr<const Chunk> chunk, const RunAnnouncement& run,
                                 const ChunkLimits& limits = {});
  static ValidatedChunk validate(Chunk chunk, const RunAnnouncement& run,
                                 const ChunkLimits& limits = {});

  const Chunk& chunk() const { return *chunk_; }
  const std::shared_ptr<const Chunk>& shared() const { return chunk_; }
  const ChunkLimits& limits() const { return limits_; }
  /// encode_chunk(chunk()), computed during validation.
  const std::string& encoded() const { return encoded_; }

  /// True when validate_chunk(chunk(), run, limits) needs not run again: the chunk's ids and
  /// channel count are the run's and it was checked under these very limits.
  bool validated_for(const RunAnnouncement& run, const ChunkLimits& limits) const;

 private:
  ValidatedChunk(std::shared_ptr<const Chunk> chunk, const ChunkLimits& limits,
                 std::string encoded);
  std::shared_ptr<const Chunk> chunk_;
  ChunkLimits limits_;
  std::string encoded_;
};

}  // namespace dynid::ingest
