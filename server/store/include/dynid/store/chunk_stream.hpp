#pragma once
// ChunkStream: the stored chunks of one run over a range of sequences, read one at a time so a
// replay never holds a whole run in memory.
//
// Contract: next() yields every sequence of the range in order, then std::nullopt. Each chunk
// is checked as it is read: decode_chunk verifies its checksum, and the decoded vehicle, run,
// sequence, first sample index, row count and checksum must match the row's own columns. A
// mismatch, undecodable bytes or a sequence missing inside the range throws CorruptionError
// naming the store and vehicle/run#sequence: a damaged chunk is never handed out. The stream
// reads through its Store's connection (SQLite: row by row; PostgreSQL: a few chunks per query):
// the Store must outlive it, and one thread uses both.
#include <cstdint>
#include <memory>
#include <optional>

#include "dynid/ingest/chunk.hpp"

namespace dynid::store {

class ChunkStream {
 public:
  ~ChunkStream();
  ChunkStream(ChunkStream&&) noexcept;
  ChunkStream& operator=(ChunkStream&&) noexcept;

  /// The next chunk of the range, or std::nullopt once the range is exhausted.
  std::optional<ingest::Chunk> next();

  struct Impl;

 private:
  friend class Store;
  explicit ChunkStream(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynid::store
