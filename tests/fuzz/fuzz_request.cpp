// Fuzz target: a request as the server receives it (dispatch.cpp, dispatch_requests ->
// accept_request): the wire sample converted by dds::from_wire (dds/conversions.hpp), then
// checked by server::parse_request (server/request_parser.hpp). No participant is created: the
// wire struct is filled directly. InputError from either step is the documented outcome (the
// server replies BAD_REQUEST with its text).
//
// Input format (text, one field per line, so the seeds are readable):
//   client \n correlation id (decimal) \n kind \n name=value \n name=value ...
// A field is copied into its bounded wire string as it is, without adding a terminator when it
// fills the bound, so unterminated strings (which a conforming peer never sends) are fuzzed
// too; at most kMaxArguments + 1 arguments are built, one past the bound.
//
// Properties of an accepted request: it converts back to the wire and reads back the same;
// every argument holds at least one value and the accessors agree with the map; split_list
// never yields an empty item or one holding a comma.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/dds/conversions.hpp"
#include "dynid/error.hpp"
#include "dynid/server/request_parser.hpp"
#include "fuzz_check.hpp"

namespace {

// The next line of `text` from `pos` (without its newline); moves `pos` past it.
std::string_view next_line(std::string_view text, std::size_t& pos) {
  pos = std::min(pos, text.size());  // past the end: empty lines
  const std::size_t end = std::min(text.find('\n', pos), text.size());
  const std::string_view line = text.substr(pos, end - pos);
  pos = end + 1;
  return line;
}

template <std::size_t N>
void fill(char (&field)[N], std::string_view value) {
  std::memset(field, 0, N);
  std::memcpy(field, value.data(), std::min(N, value.size()));
}

std::uint64_t number_of(std::string_view text) {
  std::uint64_t n = 0;
  for (const char c : text)
    if (c >= '0' && c <= '9') n = n * 10 + static_cast<std::uint64_t>(c - '0');
  return n;
}

bool same(const dynid::dds::Request& a, const dynid::dds::Request& b) {
  if (a.client != b.client || a.correlation_id != b.correlation_id || a.kind != b.kind ||
      a.arguments.size() != b.arguments.size())
    return false;
  for (std::size_t k = 0; k < a.arguments.size(); ++k)
    if (a.arguments[k].name != b.arguments[k].name || a.arguments[k].value != b.arguments[k].value)
      return false;
  return true;
}

void check_parsed(const dynid::server::ParsedRequest& parsed) {
  for (const auto& [name, values] : parsed.arguments) {
    dynid::fuzz::expect(!values.empty(), "a parsed argument holds a value");
    dynid::fuzz::expect(parsed.optional(name) == values.front(), "optional() is the first value");
    dynid::fuzz::expect(parsed.all(name) == values, "all() is every value");
    for (const auto& value : values)
      for (const auto& item : dynid::server::split_list(value))
        dynid::fuzz::expect(!item.empty() && item.find(',') == std::string::npos,
                            "split_list items are non-empty and hold no comma");
  }
  (void)parsed.json();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::size_t pos = 0;
  dynid_wire_Request sample{};
  fill(sample.client, next_line(text, pos));
  sample.correlation_id = number_of(next_line(text, pos));
  fill(sample.kind, next_line(text, pos));
  std::vector<dynid_wire_Argument> arguments;
  while (pos < text.size() && arguments.size() <= dynid_wire_kMaxArguments) {
    const std::string_view line = next_line(text, pos);
    const std::size_t equals = std::min(line.find('='), line.size());
    dynid_wire_Argument& argument = arguments.emplace_back();
    fill(argument.name, line.substr(0, equals));
    fill(argument.value, line.substr(std::min(equals + 1, line.size())));
  }
  sample.arguments._buffer = arguments.data();
  sample.arguments._length = sample.arguments._maximum = static_cast<std::uint32_t>(arguments.size());
  sample.arguments._release = false;
  try {
    const dynid::dds::Request request = dynid::dds::from_wire(sample);
    const auto wire = dynid::dds::to_wire(request);
    dynid::fuzz::expect(same(dynid::dds::from_wire(wire.data), request),
                        "a received request converts back to the wire unchanged");
    check_parsed(dynid::server::parse_request(request));
  } catch (const dynid::InputError&) {
    // documented: the server answers BAD_REQUEST with this text
  }
  return 0;
}
