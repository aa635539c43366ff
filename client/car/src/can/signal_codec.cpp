#include <bit>
#include <cfloat>
#include <cmath>
#include <dynid/can/signal_codec.hpp>
#include <dynid/error.hpp>

namespace dynid::can {
namespace {

constexpr std::uint64_t low_mask(std::uint32_t bits) {
  return bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
}

// Visits the signal's bits in chunks that stay inside one byte, most significant chunk first
// for Motorola and least significant first for Intel. f(byte, shift, width, value_shift):
// the chunk is `width` bits at `shift` in payload[byte], and bits [value_shift, +width) of raw.
template <class F>
void for_each_chunk(const Signal& s, F&& f) {
  std::uint32_t remaining = s.length;
  std::uint32_t byte = s.start_bit / 8;
  if (s.byte_order == ByteOrder::Intel) {
    std::uint32_t bit = s.start_bit % 8;
    std::uint32_t done = 0;
    while (remaining > 0) {
      const std::uint32_t width = std::min(8 - bit, remaining);
      f(byte, bit, width, done);
      done += width;
      remaining -= width;
      ++byte;
      bit = 0;
    }
    return;
  }
  std::uint32_t top = s.start_bit % 8;  // highest bit of this byte that belongs to the signal
  while (remaining > 0) {
    const std::uint32_t width = std::min(top + 1, remaining);
    remaining -= width;
    f(byte, top + 1 - width, width, remaining);
    ++byte;
    top = 7;
  }
}

std::uint64_t round_and_clamp(const Signal& s, double scaled, bool& clamped) {
  const double r = std::round(scaled);
  if (s.is_signed) {
    const double limit = std::ldexp(1.0, static_cast<int>(s.length) - 1);
    std::int64_t v = 0;
    if (r >= limit) {
      v = static_cast<std::int64_t>(low_mask(s.length - 1));
      clamped = true;
    } else if (r < -limit) {
      v = -static_cast<std::int64_t>(low_mask(s.length - 1)) - 1;
      clamped = true;
    } else {
      v = static_cast<std::int64_t>(r);
    }
    return static_cast<std::uint64_t>(v) & low_mask(s.length);
  }
  if (r >= std::ldexp(1.0, static_cast<int>(s.length))) {
    clamped = true;
    return low_mask(s.length);
  }
  if (r < 0.0) {
    clamped = true;
    return 0;
  }
  return static_cast<std::uint64_t>(r);
}

std::uint64_t float_bits(const Signal& s, double scaled, bool& clamped) {
  if (s.value_type == ValueType::Float64) return std::bit_cast<std::uint64_t>(scaled);
  if (std::fabs(scaled) > FLT_MAX) {
    clamped = true;
    scaled = std::copysign(static_cast<double>(FLT_MAX), scaled);
  }
  return std::bit_cast<std::uint32_t>(static_cast<float>(scaled));
}

}  // namespace

std::uint64_t extract_raw(const Signal& s, std::span<const std::uint8_t> payload) {
  std::uint64_t raw = 0;
  for_each_chunk(s, [&](std::uint32_t byte, std::uint32_t shift, std::uint32_t width,
                        std::uint32_t value_shift) {
    const std::uint64_t chunk = (payload[byte] >> shift) & low_mask(width);
    raw |= chunk << value_shift;
  });
  return raw;
}

void insert_raw(const Signal& s, std::uint64_t raw, std::span<std::uint8_t> payload) {
  for_each_chunk(s, [&](std::uint32_t byte, std::uint32_t shift, std::uint32_t width,
                        std::uint32_t value_shift) {
    const auto mask = static_cast<std::uint8_t>(low_mask(width) << shift);
    const auto bits = static_cast<std::uint8_t>(((raw >> value_shift) & low_mask(width)) << shift);
    payload[byte] = static_cast<std::uint8_t>((payload[byte] & ~mask) | bits);
  });
}

double raw_to_physical(const Signal& s, std::uint64_t raw) {
  double v = 0.0;
  if (s.value_type == ValueType::Float32) {
    v = static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(raw)));
  } else if (s.value_type == ValueType::Float64) {
    v = std::bit_cast<double>(raw);
  } else if (s.is_signed && s.length < 64 && ((raw >> (s.length - 1)) & 1U) != 0) {
    v = static_cast<double>(static_cast<std::int64_t>(raw | ~low_mask(s.length)));
  } else if (s.is_signed) {
    v = static_cast<double>(static_cast<std::int64_t>(raw));
  } else {
    v = static_cast<double>(raw);
  }
  return v * s.factor + s.offset;
}

RawEncoding physical_to_raw(const Signal& s, double physical) {
  if (!std::isfinite(physical))
    throw InputError("signal '" + s.name + "': value is not finite");
  if (s.factor == 0.0) throw InputError("signal '" + s.name + "': factor is 0, cannot encode");
  const double scaled = (physical - s.offset) / s.factor;
  RawEncoding out;
  out.raw = s.value_type == ValueType::Integer ? round_and_clamp(s, scaled, out.clamped)
                                               : float_bits(s, scaled, out.clamped);
  return out;
}

}  // namespace dynid::can
