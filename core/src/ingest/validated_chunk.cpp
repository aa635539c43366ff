#include "dynid/ingest/validated_chunk.hpp"

#include "dynid/error.hpp"

namespace dynid::ingest {

ValidatedChunk::ValidatedChunk(std::shared_ptr<const Chunk> chunk, const ChunkLimits& limits,
                               std::string encoded)
    : chunk_(std::move(chunk)), limits_(limits), encoded_(std::move(encoded)) {}

ValidatedChunk ValidatedChunk::validate(std::shared_ptr<const Chunk> chunk,
                                        const RunAnnouncement& run, const ChunkLimits& limits) {
  if (!chunk)
    throw InputError("chunk of " + run.vehicle + "/" + run.run + ": null (no chunk to validate)");
  std::string encoded = validate_and_encode(*chunk, run, limits);
  return ValidatedChunk(std::move(chunk), limits, std::move(encoded));
}

ValidatedChunk ValidatedChunk::validate(Chunk chunk, const RunAnnouncement& run,
                                        const ChunkLimits& limits) {
  return validate(std::make_shared<const Chunk>(std::move(chunk)), run, limits);
}

bool ValidatedChunk::validated_for(const RunAnnouncement& run, const ChunkLimits& limits) const {
  return limits == limits_ && chunk_->vehicle == run.vehicle && chunk_->run == run.run &&
         static_cast<std::size_t>(chunk_->samples.cols()) == run.channels.size();
}

}  // namespace dynid::ingest
