#include "dynid/car/chunk_builder.hpp"

#include <stdexcept>

#include "dynid/error.hpp"

namespace dynid::car {

ChunkBuilder::ChunkBuilder(std::string vehicle, std::string run, std::size_t channels,
                           std::size_t rows_per_chunk, ChunkSink sink, std::uint64_t first_sequence)
    : vehicle_(std::move(vehicle)),
      run_(std::move(run)),
      channels_(channels),
      rows_per_chunk_(rows_per_chunk),
      sink_(std::move(sink)),
      sequence_(first_sequence) {
  if (vehicle_.empty() || run_.empty()) throw InputError("chunk builder: empty vehicle or run id");
  if (channels_ == 0) throw InputError("chunk builder: no channel");
  if (rows_per_chunk_ == 0) throw InputError("chunk builder: rows_per_chunk must be > 0");
}

void ChunkBuilder::start_chunk(std::uint64_t grid_index) {
  current_ = ingest::Chunk{};
  current_.vehicle = vehicle_;
  current_.run = run_;
  current_.sequence = sequence_;
  current_.first_sample_index = grid_index;
  current_.samples.resize(static_cast<Eigen::Index>(rows_per_chunk_), static_cast<Eigen::Index>(channels_));
  current_.valid.reserve(rows_per_chunk_);
  rows_ = 0;
}

void ChunkBuilder::add_row(std::uint64_t grid_index, std::span<const double> values, bool valid) {
  if (values.size() != channels_) throw std::logic_error("chunk builder: row of the wrong width");
  if (started_ && grid_index != next_index_)
    throw std::logic_error("chunk builder: grid index " + std::to_string(grid_index) + " after " +
                           std::to_string(next_index_ - 1));
  if (rows_ == 0) start_chunk(grid_index);
  started_ = true;
  next_index_ = grid_index + 1;
  const auto r = static_cast<Eigen::Index>(rows_);
  for (std::size_t j = 0; j < channels_; ++j) current_.samples(r, static_cast<Eigen::Index>(j)) = values[j];
  current_.valid.push_back(valid ? 1 : 0);
  if (++rows_ == rows_per_chunk_) flush();
}

void ChunkBuilder::flush() {
  if (rows_ == 0) return;
  current_.samples.conservativeResize(static_cast<Eigen::Index>(rows_), Eigen::NoChange);
  current_.seal();
  ++sequence_;
  ++chunks_;
  rows_ = 0;
  sink_(std::move(current_));
}

}  // namespace dynid::car
