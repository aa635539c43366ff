#include <dynid/can/log_content.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <vector>

#include <dynid/input/ids.hpp>

#include "log_text.hpp"

namespace dynid::can {
namespace {

constexpr std::size_t kHeadBytes = 64 * 1024;
constexpr std::size_t kTableLines = 20;  // lines of a table looked at

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

std::string hex_bytes(std::string_view s, std::size_t n) {
  std::string out;
  for (std::size_t i = 0; i < std::min(n, s.size()); ++i) {
    std::array<char, 4> b{};
    std::snprintf(b.data(), b.size(), "%02X", static_cast<unsigned char>(s[i]));
    out += (i == 0 ? "" : " ") + std::string(b.data());
  }
  return out;
}

std::string compressed(std::string_view head) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 4> kMagic = {
      {{"\x1f\x8b", "a gzip-compressed file: decompress it first (gunzip)"},
       {"PK\x03\x04", "a zip archive: unpack the log from it first"},
       {std::string_view("\xfd"
                         "7zXZ\0",
                         6),
        "an xz-compressed file: decompress it first (unxz)"},
       {"BZh", "a bzip2-compressed file: decompress it first (bunzip2)"}}};
  for (const auto& [magic, what] : kMagic)
    if (starts_with(head, magic)) return std::string(what);
  return {};
}

bool binary(std::string_view head) {
  std::size_t control = 0;
  for (const char c : head) {
    const auto b = static_cast<unsigned char>(c);
    if (b == 0) return true;
    if ((b < 0x20 && b != '\t' && b != '\r' && b != '\n') || b == 0x7f) ++control;
  }
  return control * 10 > head.size();
}

// The non-blank lines of `head`, at most `n`, without their line ends.
std::vector<std::string_view> first_lines(std::string_view head, std::size_t n) {
  std::vector<std::string_view> lines;
  while (!head.empty() && lines.size() < n) {
    const std::size_t end = head.find('\n');
    const std::string_view line = detail::trim(head.substr(0, end));
    if (!line.empty()) lines.push_back(line);
    if (end == std::string_view::npos) break;
    head.remove_prefix(end + 1);
  }
  return lines;
}

std::vector<std::string_view> split(std::string_view line, char separator) {
  std::vector<std::string_view> fields;
  for (;;) {
    const std::size_t at = line.find(separator);
    fields.push_back(detail::trim(line.substr(0, at)));
    if (at == std::string_view::npos) return fields;
    line.remove_prefix(at + 1);
  }
}

// A field of a header: a name, not a number, hex bytes or a time.
bool is_name(std::string_view field) {
  return std::any_of(field.begin(), field.end(), [](char c) {
    const auto b = static_cast<unsigned char>(c);
    return std::isalpha(b) && !std::isxdigit(b) && c != 'x' && c != 'X';
  });
}

bool is_time_column(std::string_view name) {
  std::string lower;
  for (const char c : name) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower.find("time") != std::string::npos || lower.find("stamp") != std::string::npos ||
         lower.find("date") != std::string::npos || lower == "t" || lower == "ts";
}

// "a CSV table ..." when the lines split into the same fields, else "".
std::string table(const std::vector<std::string_view>& lines) {
  if (lines.size() < 2) return {};
  static constexpr std::array<std::pair<char, std::string_view>, 3> kSeparators = {
      {{',', ""}, {';', " (separated by ';')"}, {'\t', " (separated by tabs)"}}};
  for (const auto& [separator, how] : kSeparators) {
    const std::vector<std::string_view> header = split(lines.front(), separator);
    if (header.size() < 2) continue;
    const auto alike =
        std::count_if(lines.begin(), lines.end(), [&, sep = separator](std::string_view line) {
          return split(line, sep).size() == header.size();
        });
    if (static_cast<std::size_t>(alike) * 10 < lines.size() * 8) continue;  // 80 % of the lines
    const std::string convert =
        "convert it to a candump -l, Vector ASC or BLF log or a PCAN trace (.trc), which give each "
        "frame's time";
    if (!std::any_of(header.begin(), header.end(), is_name))
      return "a CSV table of " + std::to_string(header.size()) + " columns without a header" +
             std::string(how) + ", not a CAN log: " + convert;
    const std::string columns = "'" + input::printable(lines.front().substr(0, 100)) + "'";
    if (std::none_of(header.begin(), header.end(), is_time_column))
      return "a CSV table with the columns " + columns + std::string(how) +
             " and no time stamps, so it cannot be replayed: a replay needs the time of each frame "
             "(record with "
             "candump -l, or save a PCAN-View trace)";
    return "a CSV table with the columns " + columns + std::string(how) +
           ", not a CAN log: " + convert;
  }
  return {};
}

}  // namespace

std::string describe_log_content(std::string_view head) {
  if (head.empty()) return "it is empty";
  if (const std::string what = compressed(head); !what.empty()) return "it looks like " + what;
  if (binary(head))
    return "it looks like a binary file of no CAN log format read here (candump -l, Vector ASC and "
           "BLF, PCAN "
           "trace); it starts with the bytes " +
           hex_bytes(head, 8);
  const std::vector<std::string_view> lines = first_lines(head, kTableLines);
  if (lines.empty()) return "it holds only blank lines";
  const std::string_view first = lines.front();
  if (first.front() == '{' || first.front() == '[') return "it looks like JSON, not a CAN log";
  if (first.front() == '<') return "it looks like XML or HTML, not a CAN log";
  if (const std::string what = table(lines); !what.empty()) return "it looks like " + what;
  return {};
}

std::string describe_log_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::string head(kHeadBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.size() == kHeadBytes && head.find('\n') != std::string::npos)
    head.resize(head.rfind('\n') + 1);  // the line cut by the look is left out
  return describe_log_content(head);
}

}  // namespace dynid::can
