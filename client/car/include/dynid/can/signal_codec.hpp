#pragma once
// One signal's bits <-> raw value <-> physical value.
//
// Contract:
// - Intel (@1): start_bit is the least significant bit; bit n is bit n%8 of byte n/8.
// - Motorola (@0): start_bit is the most significant bit in DBC "sawtooth" numbering (bit 7 of
//   byte 0 is 7, bit 0 of byte 1 is 8); the value continues downwards to bit 0 of its byte,
//   then from bit 7 of the next byte.
// - Raw values are the bit pattern, right aligned, in a uint64. Signed integers are two's
//   complement of `length` bits; float/double signals reinterpret the 32/64 bits as IEEE 754.
// - physical = raw * factor + offset (after the sign or float interpretation).
// - extract_raw/insert_raw require a payload of at least the signal's last byte + 1
//   (Message::required_bytes covers every signal); the parser guarantees 1 <= length <= 64.
#include <cstdint>
#include <dynid/can/dbc.hpp>
#include <span>

namespace dynid::can {

std::uint64_t extract_raw(const Signal& s, std::span<const std::uint8_t> payload);
// Writes the low `length` bits of raw; other bits of the payload are kept.
void insert_raw(const Signal& s, std::uint64_t raw, std::span<std::uint8_t> payload);

double raw_to_physical(const Signal& s, std::uint64_t raw);

struct RawEncoding {
  std::uint64_t raw = 0;
  bool clamped = false;  // the value was outside what the signal's bits can hold
};
// Inverse of raw_to_physical: (physical - offset) / factor, rounded to the nearest integer
// (halves away from zero) and clamped to the raw range of the signal's bits (not to the DBC's
// [minimum|maximum], which real files often leave at 0|0). Float signals round to float32 and
// clamp to +-FLT_MAX. Throws InputError when `physical` is NaN or infinite or the factor is 0.
RawEncoding physical_to_raw(const Signal& s, double physical);

}  // namespace dynid::can
