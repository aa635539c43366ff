#pragma once
// Helpers of conversions.cpp: bounded strings and sequences of the generated wire structs,
// filled with Cyclone's allocator (so dds_sample_free releases them) and read without ever
// trusting a length.
#include <dds/dds.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <span>
#include <new>
#include <string>
#include <type_traits>

#include "dynid/error.hpp"

namespace dynid::dds::wire_fields {

/// Copies an identifier into a bounded string field (N = bound + 1); too long -> InputError.
template <std::size_t N>
void put_id(char (&field)[N], const std::string& value, const std::string& what) {
  if (value.size() >= N)
    throw InputError(what + ": '" + value + "' is longer than " + std::to_string(N - 1) +
                     " characters");
  if (value.find('\0') != std::string::npos) throw InputError(what + ": holds a NUL character");
  std::memcpy(field, value.data(), value.size());
  field[value.size()] = '\0';
}

/// Copies free text read by people into a bounded string field, cut to the bound.
template <std::size_t N>
void put_text(char (&field)[N], const std::string& value) {
  const std::size_t length = std::min(value.size(), N - 1);
  std::memcpy(field, value.data(), length);
  field[length] = '\0';
}

/// Reads a bounded string field; InputError if it has no terminator within its bound.
template <std::size_t N>
std::string get(const char (&field)[N], const std::string& what) {
  const std::size_t length = strnlen(field, N);
  if (length == N)
    throw InputError(what + ": string not terminated within its bound of " +
                     std::to_string(N - 1) + " characters");
  return std::string(field, length);
}

/// Allocates `count` zeroed elements for a bounded sequence; over `bound` -> InputError.
template <typename Sequence>
auto* allocate(Sequence& sequence, std::size_t count, std::size_t bound, const std::string& what) {
  using Element = std::remove_pointer_t<decltype(sequence._buffer)>;
  if (count > bound)
    throw InputError(what + ": " + std::to_string(count) + " elements, at most " +
                     std::to_string(bound) + " fit the wire type");
  sequence._buffer = nullptr;
  sequence._length = sequence._maximum = 0;
  if (count == 0) return static_cast<Element*>(nullptr);
  auto* buffer = static_cast<Element*>(dds_alloc(count * sizeof(Element)));
  if (buffer == nullptr) throw std::bad_alloc();
  std::memset(static_cast<void*>(buffer), 0, count * sizeof(Element));
  sequence._buffer = buffer;
  sequence._length = sequence._maximum = static_cast<uint32_t>(count);
  sequence._release = true;
  return buffer;
}

/// The elements of a received bounded sequence; InputError if its length is over `bound` or
/// it claims elements without a buffer.
template <typename Sequence>
auto elements(const Sequence& sequence, std::size_t bound, const std::string& what) {
  using Element = std::remove_pointer_t<decltype(sequence._buffer)>;
  if (sequence._length > bound)
    throw InputError(what + ": " + std::to_string(sequence._length) + " elements, bound " +
                     std::to_string(bound));
  if (sequence._length > 0 && sequence._buffer == nullptr)
    throw InputError(what + ": " + std::to_string(sequence._length) +
                     " elements claimed, no buffer");
  return std::span<const Element>(sequence._buffer, sequence._length);
}

}  // namespace dynid::dds::wire_fields
