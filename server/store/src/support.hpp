#pragma once
// Small helpers shared by the store's sources: sequence numbers between the API (unsigned)
// and SQLite (signed 64-bit, -1 for "none"), names of runs and chunks for messages, the clock,
// the CRC-32 kept beside every blob.
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "dynid/error.hpp"
#include "dynid/store/store.hpp"

namespace dynid::store::detail {

inline std::string name_of(const RunKey& key) {
  return key.vehicle + "/" + key.run;
}

inline std::string name_of(const RunKey& key, std::uint64_t sequence) {
  return name_of(key) + "#" + std::to_string(sequence);
}

/// A sequence as SQLite stores it; InputError beyond int64 (no run gets there honestly).
inline std::int64_t to_db(std::uint64_t sequence, const std::string& what) {
  if (sequence > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    throw InputError(what + ": sequence " + std::to_string(sequence) + " out of range");
  }
  return static_cast<std::int64_t>(sequence);
}

inline std::optional<std::uint64_t> from_db(std::int64_t mark) {
  if (mark < 0) return std::nullopt;
  return static_cast<std::uint64_t>(mark);
}

inline std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// CRC-32 (zlib), as an SQLite integer. zlib takes a uInt length: large inputs go in pieces.
inline std::int64_t crc32_of(std::string_view bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  while (!bytes.empty()) {
    const auto n = static_cast<uInt>(std::min<std::size_t>(bytes.size(), 1u << 30));
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data()), n);
    bytes.remove_prefix(n);
  }
  return static_cast<std::int64_t>(crc);
}

}  // namespace dynid::store::detail
