#pragma once
// Chunk file: a run's sealed chunks written one after another to a plain file, for runs without
// a server (dynid-car --chunks-out) and for comparing two pipelines' output byte for byte (the
// live SocketCAN path against the replay of a log recorded beside it, tests/vm).
//
// Format: per chunk, a u64 little-endian byte count, then ingest::encode_chunk's bytes (which
// carry their own CRC-32). No header: an empty file is a run that produced no chunk.
//
// Contract: ChunkFileWriter creates or truncates the file and throws InputError when it cannot;
// write() appends one chunk and flushes it (so a run stopped by a signal keeps every chunk written
// so far) and throws InputError on a write failure. read_chunk_file() returns the chunks in file
// order and throws InputError for a file that cannot be read, a truncated record or a chunk that
// does not decode (checksum included).
#include <filesystem>
#include <fstream>
#include <vector>

#include <dynid/ingest/chunk.hpp>

namespace dynid::car {

class ChunkFileWriter {
 public:
  explicit ChunkFileWriter(const std::filesystem::path& file);
  void write(const ingest::Chunk& chunk);
  std::uint64_t chunks() const { return chunks_; }
  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
  std::ofstream out_;
  std::uint64_t chunks_ = 0;
};

std::vector<ingest::Chunk> read_chunk_file(const std::filesystem::path& file);

}  // namespace dynid::car
