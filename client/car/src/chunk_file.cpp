#include "dynid/car/chunk_file.hpp"

#include <array>
#include <cstdint>
#include <iterator>
#include <string>

#include <dynid/error.hpp>

namespace dynid::car {

namespace {

constexpr std::size_t kLengthBytes = 8;

std::array<char, kLengthBytes> encode_length(std::uint64_t n) {
  std::array<char, kLengthBytes> out{};
  for (std::size_t i = 0; i < kLengthBytes; ++i) out[i] = static_cast<char>((n >> (8 * i)) & 0xFFU);
  return out;
}

std::uint64_t decode_length(const std::string& bytes, std::size_t at) {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < kLengthBytes; ++i)
    n |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[at + i])) << (8 * i);
  return n;
}

}  // namespace

ChunkFileWriter::ChunkFileWriter(const std::filesystem::path& file)
    : file_(file), out_(file, std::ios::binary | std::ios::trunc) {
  if (!out_) throw InputError("cannot create the chunk file " + file.string());
}

void ChunkFileWriter::write(const ingest::Chunk& chunk) {
  const std::string bytes = ingest::encode_chunk(chunk);
  const auto length = encode_length(bytes.size());
  out_.write(length.data(), static_cast<std::streamsize>(length.size()));
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out_.flush();
  if (!out_) throw InputError("cannot write chunk " + std::to_string(chunk.sequence) + " to " + file_.string());
  ++chunks_;
}

std::vector<ingest::Chunk> read_chunk_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError("cannot read the chunk file " + file.string());
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::vector<ingest::Chunk> chunks;
  std::size_t at = 0;
  while (at < bytes.size()) {
    const std::string where = file.string() + ", record " + std::to_string(chunks.size()) + " at byte " +
                              std::to_string(at);
    if (bytes.size() - at < kLengthBytes) throw InputError(where + ": truncated length");
    const std::uint64_t length = decode_length(bytes, at);
    at += kLengthBytes;
    if (length > bytes.size() - at) throw InputError(where + ": truncated chunk");
    try {
      chunks.push_back(ingest::decode_chunk(std::string_view(bytes).substr(at, length)));
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    at += length;
  }
  return chunks;
}

}  // namespace dynid::car
