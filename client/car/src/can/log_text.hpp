#pragma once
// Private helpers of the log readers (candump, ASC, BLF, TRC): words of a text line, numbers in
// them, text of a log shown in a message, civil dates.
#include <cctype>
#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <dynid/input/ids.hpp>

namespace dynid::can::detail {

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

inline std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

/// Cuts the next blank-separated word off `s`.
inline std::string_view next_word(std::string_view& s) {
  s = trim(s);
  std::size_t n = 0;
  while (n < s.size() && !is_space(s[n])) ++n;
  const std::string_view w = s.substr(0, n);
  s.remove_prefix(n);
  return w;
}

/// The blank-separated words of `s`.
inline std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> out;
  for (std::string_view w = next_word(s); !w.empty(); w = next_word(s)) out.push_back(w);
  return out;
}

/// Equal but for the case of ASCII letters.
inline bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) !=
        std::tolower(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

/// All of `s` as an unsigned number in `base` (no sign, no prefix); false when it is not one or
/// does not fit.
template <typename T>
bool parse_uint(std::string_view s, int base, T& out) {
  if (s.empty()) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out, base);
  return ec == std::errc() && end == s.data() + s.size();
}

/// Escaped: a log's bytes reach messages and log lines (input/ids.hpp printable()).
inline std::string quoted(std::string_view s) { return "'" + input::printable(s.substr(0, 40)) + "'"; }

/// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
inline std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

/// Epoch nanoseconds of a UTC date and time, or -1 when a field is out of range.
inline std::int64_t utc_ns(unsigned year, unsigned month, unsigned day, unsigned hour, unsigned minute,
                           unsigned second, unsigned ms) {
  if (year < 1970 || year > 2200 || month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 ||
      second > 60 || ms > 999)
    return -1;
  const std::int64_t s = days_from_civil(year, month, day) * 86400 + hour * 3600 + minute * 60 + second;
  return s * 1'000'000'000LL + static_cast<std::int64_t>(ms) * 1'000'000LL;
}

}  // namespace dynid::can::detail
