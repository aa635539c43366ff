#include <charconv>
#include <cmath>
#include <cstdio>
#include <dynid/can/candump.hpp>
#include <dynid/error.hpp>
#include <dynid/input/ids.hpp>
#include <dynid/input/input_file.hpp>
#include <istream>
#include <ostream>

#include "log_text.hpp"

namespace dynid::can {
namespace {

constexpr std::uint32_t kCanErrFlag = 0x20000000U;  // Linux CAN_ERR_FLAG in an 8-digit id

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

using detail::next_word;
using detail::quoted;
using detail::trim;

std::string parse_timestamp(std::string_view word, Frame& f) {
  if (word.size() < 3 || word.front() != '(' || word.back() != ')')
    return "expected a timestamp in parentheses, found " + quoted(word);
  const std::string_view digits = word.substr(1, word.size() - 2);
  for (const char c : digits)
    if ((c < '0' || c > '9') && c != '.') return "bad timestamp " + quoted(word);
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), f.timestamp);
  if (ec != std::errc() || end != digits.data() + digits.size() || !std::isfinite(f.timestamp))
    return "bad timestamp " + quoted(word);
  return {};
}

std::string parse_id(std::string_view hex, Frame& f) {
  if (hex.size() != 3 && hex.size() != 8)
    return "the id must have 3 (standard) or 8 (extended) hex digits, found " + quoted(hex);
  std::uint32_t id = 0;
  for (const char c : hex) {
    if (hex_value(c) < 0) return "bad hex digit in the id " + quoted(hex);
    id = id * 16 + static_cast<std::uint32_t>(hex_value(c));
  }
  f.extended = hex.size() == 8;
  if (f.extended && (id & kCanErrFlag) != 0) return "error frame (CAN_ERR_FLAG) " + quoted(hex);
  if (id > (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId))
    return "id " + quoted(hex) + " is out of range";
  f.id = id;
  return {};
}

// Hex byte pairs, optionally separated by '.', into f.data.
std::string parse_data(std::string_view hex, std::size_t max_bytes, Frame& f) {
  std::size_t n = 0;
  std::size_t i = 0;
  while (i < hex.size()) {
    if (hex[i] == '.') {
      ++i;
      continue;
    }
    if (hex[i] == '_' && !f.fd && n == Frame::kMaxClassicData && i + 2 == hex.size() &&
        hex_value(hex[i + 1]) > 8)
      break;  // "_<dlc>": classic frame with a raw DLC 9..15 carries 8 bytes
    if (i + 1 >= hex.size() || hex_value(hex[i]) < 0 || hex_value(hex[i + 1]) < 0)
      return "bad hex data at " + quoted(hex.substr(i)) + " (bytes are two hex digits)";
    if (n == max_bytes)
      return "payload longer than " + std::to_string(max_bytes) + " bytes" +
             (f.fd ? "" : " (classic CAN; CAN FD uses '##')");
    f.data[n++] = static_cast<std::uint8_t>(hex_value(hex[i]) * 16 + hex_value(hex[i + 1]));
    i += 2;
  }
  f.length = static_cast<std::uint8_t>(n);
  if (f.fd && !is_valid_fd_length(n))
    return "CAN FD payload of " + std::to_string(n) + " bytes is not a valid FD length";
  return {};
}

std::string parse_frame(std::string_view word, Frame& f) {
  const std::size_t hash = word.find('#');
  if (hash == std::string_view::npos) return "expected <id>#<data>, found " + quoted(word);
  if (std::string err = parse_id(word.substr(0, hash), f); !err.empty()) return err;
  std::string_view rest = word.substr(hash + 1);
  f.fd = !rest.empty() && rest.front() == '#';
  if (f.fd) {
    if (rest.size() < 2 || hex_value(rest[1]) < 0) return "CAN FD frame without its flags nibble";
    f.fd_flags = static_cast<std::uint8_t>(hex_value(rest[1]));
    return parse_data(rest.substr(2), Frame::kMaxFdData, f);
  }
  if (!rest.empty() && (rest.front() == 'R' || rest.front() == 'r')) {
    f.rtr = true;
    const bool has_dlc = rest.size() == 2 && hex_value(rest[1]) >= 0 && hex_value(rest[1]) <= 8;
    if (rest.size() > 2 || (rest.size() == 2 && !has_dlc))
      return "bad remote frame " + quoted(word) + " (expected R or R<dlc 0..8>)";
    f.length = has_dlc ? static_cast<std::uint8_t>(hex_value(rest[1])) : 0;
    return {};
  }
  return parse_data(rest, Frame::kMaxClassicData, f);
}

// Largest timestamp whose microsecond count fits a long long (2^63 us, about 292,000 years).
constexpr double kMaxWritableSeconds = 9.2e12;

void check_writable(const Frame& f) {
  if (!std::isfinite(f.timestamp) || f.timestamp < 0.0)
    throw InputError("candump writer: timestamp " + std::to_string(f.timestamp) +
                     " is not a finite non-negative number");
  // The line holds whole microseconds as a 64-bit count; past that llround's result is garbage
  // and the line written unreadable (a log line "(170000000046408.5) ..." read back and
  // rewritten as "(-9223372036854.-775808)": found by tests/fuzz/fuzz_candump).
  if (f.timestamp >= kMaxWritableSeconds)
    throw InputError("candump writer: timestamp " + std::to_string(f.timestamp) +
                     " s is too large for the log's microsecond count");
  if (f.interface_name().empty()) throw InputError("candump writer: frame has no interface name");
  if (f.id > (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId))
    throw InputError("candump writer: id " + std::to_string(f.id) + " too large for " +
                     (f.extended ? "a 29-bit id" : "an 11-bit id"));
  if (f.fd ? !is_valid_fd_length(f.length) : f.length > Frame::kMaxClassicData)
    throw InputError("candump writer: payload length " + std::to_string(f.length) +
                     " invalid for " + (f.fd ? "CAN FD" : "classic CAN"));
  if (f.fd && f.rtr) throw InputError("candump writer: CAN FD has no remote frames");
}

}  // namespace

std::string parse_candump_line(std::string_view line, Frame& frame) {
  frame = Frame{};
  std::string_view rest = line;
  if (std::string err = parse_timestamp(next_word(rest), frame); !err.empty()) return err;
  const std::string_view iface = next_word(rest);
  if (iface.empty()) return "missing interface name after the timestamp";
  if (!frame.set_interface_name(iface))
    return "interface name " + quoted(iface) + " is longer than 15 characters";
  const std::string_view word = next_word(rest);
  if (word.empty()) return "missing frame after the interface name";
  if (std::string err = parse_frame(word, frame); !err.empty()) return err;
  // python-can's candump writer adds the direction, " R" (received) or " T" (sent).
  const std::string_view tail = trim(rest);
  if (!tail.empty() && tail != "R" && tail != "T") return "unexpected text after the frame: " + quoted(tail);
  return {};
}

std::string format_candump_line(const Frame& f) {
  check_writable(f);
  const long long micros = std::llround(f.timestamp * 1e6);
  char head[48];
  std::snprintf(head, sizeof head, "(%010lld.%06lld) ", micros / 1000000, micros % 1000000);
  char id[16];
  std::snprintf(id, sizeof id, f.extended ? "%08X" : "%03X", static_cast<unsigned>(f.id));
  std::string out = std::string(head) + std::string(f.interface_name()) + " " + id + "#";
  static constexpr char kHex[] = "0123456789ABCDEF";
  if (f.rtr) return out + "R" + (f.length > 0 ? std::string(1, kHex[f.length]) : "");
  if (f.fd) out += std::string("#") + kHex[f.fd_flags & 0xF];
  for (const std::uint8_t b : f.payload()) {
    out.push_back(kHex[b >> 4]);
    out.push_back(kHex[b & 0xF]);
  }
  return out;
}

std::string CandumpReader::parse_line(std::string_view line, Frame& frame, bool& is_frame) {
  is_frame = true;
  return parse_candump_line(line, frame);
}

void CandumpWriter::write(const Frame& frame) { out_ << format_candump_line(frame) << '\n'; }

}  // namespace dynid::can
