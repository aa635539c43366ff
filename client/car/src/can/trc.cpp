#include <dynid/can/trc.hpp>

#include <algorithm>
#include <array>

#include "log_text.hpp"

namespace dynid::can {
namespace {

using detail::iequals;
using detail::parse_uint;
using detail::quoted;
using detail::trim;
using detail::words;

constexpr std::int64_t kNsPerDay = 86'400'000'000'000LL;
constexpr std::int64_t kDaysTo1970 = 25569;  // 1899-12-30 to 1970-01-01
// 1899-12-30 to 2200-01-01: start + offset in nanoseconds stays within int64 (to 2262).
constexpr std::int64_t kDaysTo2200 = 109'575;
constexpr std::string_view kColumnLetters = "NOTBIdRlLD";

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

// The value of a ";$KEY=value" line, trimmed.
std::string_view header_value(std::string_view line) {
  const std::size_t eq = line.find('=');
  return eq == std::string_view::npos ? std::string_view() : trim(line.substr(eq + 1));
}

// "<ms>[.<up to 6 digits>]" -> nanoseconds (up to about 31 years).
bool parse_offset_ns(std::string_view s, std::int64_t& ns) {
  const std::size_t dot = s.find('.');
  std::int64_t ms = 0;
  if (!parse_uint(s.substr(0, dot), 10, ms) || ms < 0 || ms > 1'000'000'000'000LL) return false;
  std::int64_t frac = 0;
  if (dot != std::string_view::npos) {
    const std::string_view f = s.substr(dot + 1);
    if (f.empty() || f.size() > 6 || !parse_uint(f, 10, frac) || frac < 0) return false;
    for (std::size_t i = f.size(); i < 6; ++i) frac *= 10;
  }
  ns = ms * 1'000'000LL + frac;
  return true;
}

// The payload length of a CAN FD data length code.
std::size_t fd_length(unsigned dlc) {
  static constexpr std::array<std::uint8_t, 16> kLength = {0, 1,  2,  3,  4,  5,  6,  7,
                                                           8, 12, 16, 20, 24, 32, 48, 64};
  return kLength[dlc & 15U];
}

bool is_decimal(std::string_view s) {
  if (s.empty()) return false;
  for (const char c : s)
    if (c < '0' || c > '9') return false;
  return true;
}

// An id of 1..8 hex digits; more than 4 digits is a 29-bit id.
std::string parse_id(std::string_view word, Frame& f) {
  if (word.size() > 8 || !parse_uint(word, 16, f.id)) return "bad id " + quoted(word);
  f.extended = word.size() > 4;
  if (f.id > (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId))
    return "id " + quoted(word) + " is out of range for " + (f.extended ? "a 29" : "an 11") +
           "-bit id";
  return {};
}

// `length` bytes of two hex digits each from w[first], and nothing after them.
std::string parse_bytes(const std::vector<std::string_view>& w, std::size_t first,
                        std::size_t length, Frame& f) {
  if (w.size() < first + length)
    return "frame has " + std::to_string(w.size() > first ? w.size() - first : 0) +
           " data bytes, fewer than its length " + std::to_string(length);
  if (w.size() > first + length)
    return "frame has more data bytes than its length " + std::to_string(length) + ": " +
           quoted(w[first + length]);
  for (std::size_t k = 0; k < length; ++k) {
    unsigned b = 0;
    if (w[first + k].size() != 2 || !parse_uint(w[first + k], 16, b))
      return "bad data byte " + quoted(w[first + k]);
    f.data[k] = static_cast<std::uint8_t>(b);
  }
  f.length = static_cast<std::uint8_t>(length);
  return {};
}

// Bus n (1..99) is the interface "can<n-1>".
std::string set_bus(std::string_view word, Frame& f) {
  unsigned bus = 0;
  if (!parse_uint(word, 10, bus) || bus < 1 || bus > 99)
    return "bad bus " + quoted(word) + " (1..99)";
  f.set_interface_name("can" + std::to_string(bus - 1));
  return {};
}

}  // namespace

std::optional<std::int64_t> parse_trc_start_time(std::string_view days) {
  days = trim(days);
  if (!days.empty() && days.back() == ';') days = trim(days.substr(0, days.size() - 1));
  const std::size_t dot = days.find('.');
  const std::string_view whole = days.substr(0, dot);
  std::int64_t d = 0;
  if (!is_decimal(whole) || whole.size() > 7 || !parse_uint(whole, 10, d)) return std::nullopt;
  // The fraction to 12 digits (1e-12 day is 86 ns, below the microsecond kept).
  std::int64_t frac = 0;
  if (dot != std::string_view::npos) {
    const std::string_view f = days.substr(dot + 1);
    if (f.empty() || !is_decimal(f)) return std::nullopt;
    const std::string_view kept = f.substr(0, 12);
    if (!parse_uint(kept, 10, frac)) return std::nullopt;
    for (std::size_t i = kept.size(); i < 12; ++i) frac *= 10;
  }
  if (d < kDaysTo1970 || d >= kDaysTo2200) return std::nullopt;
  // frac / 1e12 days = frac * 8.64e10 / 1e12 us = frac * 864 / 1e4 us, rounded to the microsecond.
  const std::int64_t us = (frac * 864 + 5'000) / 10'000;
  return (d - kDaysTo1970) * kNsPerDay + us * 1000;
}

bool looks_like_trc(std::string_view head) {
  std::size_t i = 0;
  while (i < head.size() && detail::is_space(head[i])) ++i;
  head.remove_prefix(i);
  if (starts_with(head, ";$FILEVERSION=") || starts_with(head, ";$STARTTIME=")) return true;
  // The leading comment block of a 1.0 file names the program that wrote it.
  while (!head.empty() && head.front() == ';') {
    const std::size_t end = head.find('\n');
    const std::string_view line = head.substr(0, end);
    if (line.find("PCAN") != std::string_view::npos || line.find("PEAK") != std::string_view::npos)
      return true;
    if (end == std::string_view::npos) break;
    head.remove_prefix(end + 1);
  }
  return false;
}

std::string_view TrcReader::version() const {
  switch (version_) {
    case Version::V1_0:
      return "1.0";
    case Version::V1_1:
      return "1.1";
    case Version::V1_2:
      return "1.2";
    case Version::V1_3:
      return "1.3";
    case Version::V2_0:
      return "2.0";
    case Version::V2_1:
      return "2.1";
  }
  return "?";
}

std::string TrcReader::set_columns(std::string_view letters) {
  std::string columns;
  std::string_view rest = letters;
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view letter = trim(rest.substr(0, comma));
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    if (letter.size() != 1 || kColumnLetters.find(letter[0]) == std::string_view::npos ||
        columns.find(letter[0]) != std::string::npos)
      return "bad $COLUMNS " + quoted(letters) + ": " + quoted(letter) +
             " is no column letter or comes twice (N O T B I d R l L D)";
    columns += letter[0];
  }
  for (const char needed : std::string_view("OTID"))
    if (columns.find(needed) == std::string::npos)
      return "bad $COLUMNS " + quoted(letters) + ": no column '" + std::string(1, needed) + "'";
  if (columns.back() != 'D')
    return "bad $COLUMNS " + quoted(letters) + ": the data bytes (D) come last";
  if ((columns.find('l') == std::string::npos) == (columns.find('L') == std::string::npos))
    return "bad $COLUMNS " + quoted(letters) + ": one of 'l' (length) or 'L' (DLC) is needed";
  columns_ = std::move(columns);
  return {};
}

std::string TrcReader::parse_header(std::string_view line) {
  if (starts_with(line, ";$FILEVERSION")) {
    const std::string_view v = header_value(line);
    static constexpr std::array<std::pair<std::string_view, Version>, 6> kVersions = {
        {{"1.0", Version::V1_0},
         {"1.1", Version::V1_1},
         {"1.2", Version::V1_2},
         {"1.3", Version::V1_3},
         {"2.0", Version::V2_0},
         {"2.1", Version::V2_1}}};
    for (const auto& [name, version] : kVersions)
      if (v == name) {
        version_ = version;
        if (columns_.empty() && version == Version::V2_0) columns_ = "NOTIdlD";
        if (columns_.empty() && version == Version::V2_1) columns_ = "NOTBIdRLD";
        return {};
      }
    return "unknown PCAN trace file version " + quoted(v) +
           " (1.0, 1.1, 1.2, 1.3, 2.0 and 2.1 are read)";
  }
  if (starts_with(line, ";$STARTTIME")) {
    start_ns_ = parse_trc_start_time(header_value(line));
    if (!start_ns_)
      return "bad $STARTTIME " + quoted(header_value(line)) +
             " (days since 1899-12-30, from 1970 to 2199)";
    return {};
  }
  if (starts_with(line, ";$COLUMNS")) return set_columns(header_value(line));
  return {};  // a comment
}

std::string TrcReader::parse_line(std::string_view line, Frame& f, bool& is_frame) {
  is_frame = false;
  line = trim(line);
  if (line.front() == ';') return parse_header(line);
  const std::vector<std::string_view> w = words(line);
  f = Frame{};
  f.set_interface_name("can0");
  std::string reason = version_ == Version::V2_0 || version_ == Version::V2_1
                           ? parse_v2(w, f, is_frame)
                           : parse_v1(w, f, is_frame);
  if (reason.empty() && !is_frame) ++skipped_;
  return reason;
}

// <n>) <offset> [<bus>] [<type>] <id> [<reserved>] <dlc> <bytes...>, by the version.
std::string TrcReader::parse_v1(const std::vector<std::string_view>& w, Frame& f, bool& is_frame) {
  const bool has_type = version_ != Version::V1_0;
  const bool has_bus = version_ == Version::V1_2 || version_ == Version::V1_3;
  const bool has_reserved = version_ == Version::V1_3;
  const std::size_t bus_at = 2;
  const std::size_t type_at = has_bus ? 3 : 2;
  const std::size_t id_at = type_at + (has_type ? 1 : 0);
  const std::size_t dlc_at = id_at + (has_reserved ? 2 : 1);
  if (w[0].size() < 2 || w[0].back() != ')' || !is_decimal(w[0].substr(0, w[0].size() - 1)))
    return "expected a comment ';' or a record '<number>) <offset> ...', found " + quoted(w[0]);
  if (w.size() < 2) return "record without a time offset";
  std::int64_t offset = 0;
  if (!parse_offset_ns(w[1], offset)) return "bad time offset " + quoted(w[1]) + " (milliseconds)";
  if (has_type) {
    if (w.size() <= type_at) return "record without a type";
    if (iequals(w[type_at], "Warng") || iequals(w[type_at], "Error")) return {};  // no data frame
    if (!iequals(w[type_at], "Rx") && !iequals(w[type_at], "Tx"))
      return "unknown record type " + quoted(w[type_at]) + " (Rx, Tx, Warng, Error)";
  }
  if (w.size() <= dlc_at)
    return "record too short for a version " + std::string(version()) + " frame";
  if (has_bus)
    if (std::string bad = set_bus(w[bus_at], f); !bad.empty()) return bad;
  if (version_ == Version::V1_0 && w[id_at] == "FFFFFFFF") return {};  // a bus warning
  if (std::string bad = parse_id(w[id_at], f); !bad.empty()) return bad;
  unsigned dlc = 0;
  if (!parse_uint(w[dlc_at], 10, dlc) || dlc > 8)
    return "bad data length " + quoted(w[dlc_at]) + " (0..8)";
  if (w.size() > dlc_at + 1 && (iequals(w[dlc_at + 1], "RTR") || iequals(w[dlc_at + 1], "ERROR")))
    return {};  // a remote request or an error frame
  if (std::string bad = parse_bytes(w, dlc_at + 1, dlc, f); !bad.empty()) return bad;
  f.timestamp = seconds_from_ns(start_ns_.value_or(0) + offset);
  is_frame = true;
  return {};
}

// The $COLUMNS' words; the data bytes are the last column.
std::string TrcReader::parse_v2(const std::vector<std::string_view>& w, Frame& f, bool& is_frame) {
  const auto at = [this](char letter) { return columns_.find(letter); };
  const std::size_t type_at = at('T');
  if (w.size() <= std::max(type_at, at('O')))
    return "record too short: expected the columns " + quoted(std::string_view(columns_)) +
           " of $COLUMNS";
  if (const std::size_t n = at('N'); n != std::string::npos && !is_decimal(w[n]))
    return "expected a comment ';' or a record '<number> <offset> <type> ...', found " +
           quoted(w[n]);
  std::int64_t offset = 0;
  if (!parse_offset_ns(w[at('O')], offset))
    return "bad time offset " + quoted(w[at('O')]) + " (milliseconds)";
  const std::string_view type = w[type_at];
  for (const std::string_view other : {"RR", "ST", "EC", "ER", "EV"})
    if (type == other) return {};  // no data frame
  const bool fd = type == "FD" || type == "FB" || type == "FE" || type == "BI";
  if (!fd && type != "DT")
    return "unknown record type " + quoted(type) + " (DT, FD, FB, FE, BI, RR, ST, EC, ER, EV)";
  const std::size_t data_at = at('D');
  if (w.size() < data_at)
    return "record too short: expected the columns " + quoted(std::string_view(columns_)) +
           " of $COLUMNS";
  f.fd = fd;
  if (type == "FB" || type == "BI") f.fd_flags |= Frame::kFdBrs;
  if (type == "FE" || type == "BI") f.fd_flags |= Frame::kFdEsi;
  if (const std::size_t bus = at('B'); bus != std::string::npos)
    if (std::string bad = set_bus(w[bus], f); !bad.empty()) return bad;
  if (std::string bad = parse_id(w[at('I')], f); !bad.empty()) return bad;
  if (const std::size_t d = at('d'); d != std::string::npos && w[d] != "Rx" && w[d] != "Tx")
    return "expected Rx or Tx, found " + quoted(w[d]);
  std::size_t length = 0;
  unsigned n = 0;
  if (const std::size_t l = at('l'); l != std::string::npos) {
    if (!parse_uint(w[l], 10, n) || (fd ? !is_valid_fd_length(n) : n > 8))
      return "bad data length " + quoted(w[l]) +
             (fd ? " (a CAN FD length: 0..8, 12, 16, 20, 24, 32, 48, 64)" : " (0..8)");
    length = n;
  } else {
    const std::size_t dlc = at('L');
    if (!parse_uint(w[dlc], 10, n) || n > (fd ? 15U : 8U))
      return "bad data length code " + quoted(w[dlc]) + (fd ? " (0..15)" : " (0..8)");
    length = fd_length(n);
  }
  if (std::string bad = parse_bytes(w, data_at, length, f); !bad.empty()) return bad;
  f.timestamp = seconds_from_ns(start_ns_.value_or(0) + offset);
  is_frame = true;
  return {};
}

}  // namespace dynid::can
