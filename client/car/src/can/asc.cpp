#include <dynid/can/asc.hpp>

#include <array>

#include "log_text.hpp"

namespace dynid::can {
namespace {

using detail::iequals;
using detail::next_word;
using detail::parse_uint;
using detail::quoted;
using detail::trim;
using detail::words;

bool starts_with_word(std::string_view line, std::string_view word) {
  std::string_view rest = line;
  return iequals(next_word(rest), word);
}

// "<seconds>[.<up to 9 digits>]" -> nanoseconds.
bool parse_time_ns(std::string_view s, std::int64_t& ns) {
  const std::size_t dot = s.find('.');
  const std::string_view whole = s.substr(0, dot);
  std::int64_t seconds = 0;
  if (!parse_uint(whole, 10, seconds) || seconds > 9'000'000'000LL) return false;
  std::int64_t frac = 0;
  if (dot != std::string_view::npos) {
    const std::string_view f = s.substr(dot + 1);
    if (f.empty() || f.size() > 9 || !parse_uint(f, 10, frac)) return false;
    for (std::size_t i = f.size(); i < 9; ++i) frac *= 10;
  }
  ns = seconds * 1'000'000'000LL + frac;
  return true;
}

}  // namespace

std::optional<std::int64_t> parse_asc_date(std::string_view date) {
  static constexpr std::array<std::string_view, 12> kMonths = {"jan", "feb", "mar", "apr", "may", "jun",
                                                               "jul", "aug", "sep", "oct", "nov", "dec"};
  const auto w = words(date);
  // [weekday] month day time [am|pm] year
  std::size_t i = 0;
  if (w.size() < 4) return std::nullopt;
  unsigned month = 0;
  for (std::size_t k = 0; k < 2 && month == 0 && i < w.size(); ++k, ++i)
    for (unsigned m = 0; m < 12; ++m)
      if (iequals(w[i].substr(0, 3), kMonths[m]) && w[i].size() >= 3) month = m + 1;
  if (month == 0 || i + 2 > w.size()) return std::nullopt;
  unsigned day = 0;
  if (!parse_uint(w[i++], 10, day) || day < 1 || day > 31) return std::nullopt;
  if (i >= w.size()) return std::nullopt;
  const std::string_view clock = w[i++];
  unsigned hh = 0, mm = 0, ss = 0, ms = 0;
  {
    const std::size_t c1 = clock.find(':');
    const std::size_t c2 = clock.find(':', c1 == std::string_view::npos ? c1 : c1 + 1);
    if (c1 == std::string_view::npos || c2 == std::string_view::npos) return std::nullopt;
    const std::size_t dot = clock.find('.', c2);
    if (!parse_uint(clock.substr(0, c1), 10, hh) || !parse_uint(clock.substr(c1 + 1, c2 - c1 - 1), 10, mm) ||
        !parse_uint(clock.substr(c2 + 1, dot == std::string_view::npos ? std::string_view::npos : dot - c2 - 1), 10, ss))
      return std::nullopt;
    if (dot != std::string_view::npos) {
      std::string_view f = clock.substr(dot + 1);
      if (f.empty() || f.size() > 3 || !parse_uint(f, 10, ms)) return std::nullopt;
      for (std::size_t k = f.size(); k < 3; ++k) ms *= 10;
    }
  }
  if (i < w.size() && (iequals(w[i], "am") || iequals(w[i], "pm"))) {
    if (hh < 1 || hh > 12) return std::nullopt;
    const bool pm = iequals(w[i], "pm");
    hh = hh % 12 + (pm ? 12 : 0);
    ++i;
  }
  if (i >= w.size()) return std::nullopt;
  int year = 0;
  if (!parse_uint(w[i], 10, year)) return std::nullopt;
  const std::int64_t ns = detail::utc_ns(static_cast<unsigned>(year), month, day, hh, mm, ss, ms);
  if (ns < 0) return std::nullopt;
  return ns;
}

std::string AscReader::parse_line(std::string_view line, Frame& f, bool& is_frame) {
  is_frame = false;
  line = trim(line);
  if (line.empty() || line.substr(0, 2) == "//") return {};
  if (starts_with_word(line, "date")) {
    std::string_view rest = line;
    next_word(rest);
    if (!start_ns_) start_ns_ = parse_asc_date(rest);
    return {};
  }
  if (starts_with_word(line, "base")) {
    const auto w = words(line);
    if (w.size() < 2 || (!iequals(w[1], "hex") && !iequals(w[1], "dec")))
      return "bad 'base' line " + quoted(line) + " (expected base hex|dec  timestamps absolute|relative)";
    hex_ = iequals(w[1], "hex");
    for (std::size_t i = 2; i + 1 < w.size(); ++i)
      if (iequals(w[i], "timestamps")) relative_ = iequals(w[i + 1], "relative");
    return {};
  }
  if (starts_with_word(line, "internal") || starts_with_word(line, "no")) return {};
  if (starts_with_word(line, "Begin")) {
    std::string_view rest = line;
    next_word(rest);
    if (!iequals(next_word(rest), "Triggerblock")) return "unknown line " + quoted(line);
    if (const auto start = parse_asc_date(rest)) start_ns_ = start;
    previous_ns_ = 0;
    return {};
  }
  if (starts_with_word(line, "End")) return {};

  std::string_view rest = line;
  const std::string_view time_word = next_word(rest);
  std::int64_t t = 0;
  if (!parse_time_ns(time_word, t)) return "expected a header line or '<time> <event>', found " + quoted(line);
  if (relative_) t += previous_ns_;
  previous_ns_ = t;
  const std::vector<std::string_view> w = words(rest);
  if (w.empty()) return "event without anything after its time";
  if (iequals(w[0], "Start") || iequals(w[0], "SV:") || iequals(w[0], "Log")) return {};
  const bool fd = iequals(w[0], "CANFD");
  std::size_t i = fd ? 1 : 0;
  unsigned channel = 0;
  if (i >= w.size() || !parse_uint(w[i], 10, channel)) return "unknown event " + quoted(rest);
  ++i;
  if (i < w.size() && (iequals(w[i], "Statistic:") || iequals(w[i], "Chip"))) return {};
  if (i < w.size() && iequals(w[i], "ErrorFrame")) return "error frame on channel " + std::to_string(channel);
  if (channel < 1 || channel > 99) return "channel " + std::to_string(channel) + " out of 1..99";
  f = Frame{};
  f.set_interface_name("can" + std::to_string(channel - 1));
  f.fd = fd;
  std::string_view id_word;
  if (fd) {  // CANFD <ch> <dir> <id> ...
    if (i + 1 >= w.size()) return "CAN FD line too short";
    if (!iequals(w[i], "Rx") && !iequals(w[i], "Tx")) return "expected Rx or Tx, found " + quoted(w[i]);
    id_word = w[i + 1];
    i += 2;
  } else {  // <ch> <id> <dir> ...
    if (i + 1 >= w.size()) return "frame line too short: " + quoted(rest);
    id_word = w[i];
    if (!iequals(w[i + 1], "Rx") && !iequals(w[i + 1], "Tx"))
      return "unknown event " + quoted(rest) + " (a frame is <ch> <id> Rx|Tx d <dlc> <bytes>)";
    i += 2;
  }
  f.extended = !id_word.empty() && (id_word.back() == 'x' || id_word.back() == 'X');
  if (f.extended) id_word.remove_suffix(1);
  if (id_word.size() > 8 || !parse_uint(id_word, hex_ ? 16 : 10, f.id)) return "bad id " + quoted(id_word);
  if (f.id > (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId))
    return "id " + quoted(id_word) + " is out of range";
  const int base = hex_ ? 16 : 10;
  std::size_t length = 0;
  if (fd) {
    // [<symbolic name>] <brs> <esi> <dlc> <data length> <bytes...>
    if (i < w.size() && w[i] != "0" && w[i] != "1") ++i;  // a symbolic name
    if (i + 4 > w.size()) return "CAN FD line too short";
    unsigned brs = 0, esi = 0, dlc = 0;
    if (!parse_uint(w[i], 10, brs) || !parse_uint(w[i + 1], 10, esi) || brs > 1 || esi > 1)
      return "bad CAN FD brs/esi " + quoted(w[i]) + " " + quoted(w[i + 1]);
    if (!parse_uint(w[i + 2], 16, dlc) || dlc > 15) return "bad CAN FD dlc " + quoted(w[i + 2]);
    if (!parse_uint(w[i + 3], 10, length) || !is_valid_fd_length(length))
      return "bad CAN FD data length " + quoted(w[i + 3]);
    f.fd_flags = static_cast<std::uint8_t>((brs ? Frame::kFdBrs : 0) | (esi ? Frame::kFdEsi : 0));
    i += 4;
  } else {
    if (i >= w.size()) return "frame without 'd <dlc>' or 'r'";
    if (iequals(w[i], "r")) {
      f.rtr = true;
      unsigned dlc = 0;
      if (i + 1 < w.size() && (!parse_uint(w[i + 1], 16, dlc) || dlc > 8)) return "bad remote dlc " + quoted(w[i + 1]);
      f.length = static_cast<std::uint8_t>(dlc);
      f.timestamp = 0;
      length = 0;
      i = w.size();
    } else {
      if (!iequals(w[i], "d") || i + 1 >= w.size()) return "expected 'd <dlc>' after the direction, found " + quoted(w[i]);
      unsigned dlc = 0;
      if (!parse_uint(w[i + 1], 16, dlc) || dlc > 15) return "bad dlc " + quoted(w[i + 1]);
      length = dlc > 8 ? 8 : dlc;
      i += 2;
    }
  }
  if (!f.rtr) {
    if (w.size() < i + length) return "frame has fewer data bytes than its length " + std::to_string(length);
    for (std::size_t k = 0; k < length; ++k) {
      unsigned b = 0;
      if (!parse_uint(w[i + k], base, b) || b > 255 || (hex_ && w[i + k].size() != 2))
        return "bad data byte " + quoted(w[i + k]);
      f.data[k] = static_cast<std::uint8_t>(b);
    }
    f.length = static_cast<std::uint8_t>(length);
  }
  f.timestamp = seconds_from_ns(start_ns_.value_or(0) + t);
  is_frame = true;
  return {};
}

}  // namespace dynid::can
