#pragma once
// ChunkBuilder: grid rows -> sealed ingest::Chunks of a fixed number of rows.
//
// Contract: rows must arrive with consecutive grid indices (the Resampler guarantees it; anything
// else is a programming error and throws std::logic_error). A chunk is handed to the sink as
// soon as it holds rows_per_chunk rows; flush() hands over a final, shorter chunk. Chunks carry
// consecutive sequence numbers from first_sequence, first_sample_index = grid index of row 0,
// and are sealed (CRC) before they leave.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include <dynid/ingest/chunk.hpp>

namespace dynid::car {

class ChunkBuilder {
 public:
  using ChunkSink = std::function<void(ingest::Chunk&&)>;

  /// Throws InputError for an empty vehicle or run id, no channel or rows_per_chunk == 0.
  ChunkBuilder(std::string vehicle, std::string run, std::size_t channels,
               std::size_t rows_per_chunk, ChunkSink sink, std::uint64_t first_sequence = 0);

  void add_row(std::uint64_t grid_index, std::span<const double> values, bool valid);
  void flush();

  std::uint64_t next_sequence() const { return sequence_; }
  std::uint64_t chunks() const { return chunks_; }

 private:
  void start_chunk(std::uint64_t grid_index);

  std::string vehicle_;
  std::string run_;
  std::size_t channels_;
  std::size_t rows_per_chunk_;
  ChunkSink sink_;
  std::uint64_t sequence_;
  std::uint64_t chunks_ = 0;
  std::uint64_t next_index_ = 0;
  bool started_ = false;
  ingest::Chunk current_;
  std::size_t rows_ = 0;
};

}  // namespace dynid::car
