#include "chunk_checksum.hpp"

#include <zlib.h>

#include <cstring>
#include <string>

namespace peer {

namespace {

// Little-endian whatever the host, as the encoding is defined.
template <typename T>
void put(std::string& out, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
#if __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
#endif
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

void put_string(std::string& out, const std::string& s) {
  put<std::uint32_t>(out, static_cast<std::uint32_t>(s.size()));
  out += s;
}

}  // namespace

std::uint32_t chunk_checksum(const dynid::wire::Chunk& chunk) {
  std::string body = "DYNIDCHK";
  put<std::uint16_t>(body, 1);
  put_string(body, chunk.vehicle().to_string());
  put_string(body, chunk.run().to_string());
  put<std::uint64_t>(body, chunk.sequence_number());
  put<std::uint64_t>(body, chunk.first_sample_index());
  put<std::uint64_t>(body, chunk.rows());
  put<std::uint64_t>(body, chunk.channels());
  for (const double v : chunk.data()) put<double>(body, v);
  put<std::uint64_t>(body, chunk.valid().size());
  for (const std::uint8_t f : chunk.valid()) put<std::uint8_t>(body, f);
  const auto crc =
      crc32(0L, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size()));
  return static_cast<std::uint32_t>(crc);
}

}  // namespace peer
