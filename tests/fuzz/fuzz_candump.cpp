// Fuzz target: the candump log reader (can/candump.hpp) on arbitrary text. The reader's
// contract is that it never throws for a bad line, so any exception from it is a finding.
// Every frame it reads must survive a round trip: formatting it (InputError is documented for
// a frame the format cannot express) and reading the line back gives the same line again.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "dynid/can/candump.hpp"
#include "dynid/error.hpp"
#include "fuzz_check.hpp"

namespace {

void round_trip(const dynid::can::Frame& frame) {
  std::string line;
  try {
    line = dynid::can::format_candump_line(frame);
  } catch (const dynid::InputError&) {
    return;  // documented: a frame candump's format cannot write
  }
  dynid::can::Frame again;
  dynid::fuzz::expect(dynid::can::parse_candump_line(line, again).empty(),
                      "the reader accepts the line the writer made of a frame it read");
  dynid::fuzz::expect(dynid::can::format_candump_line(again) == line,
                      "format(parse(format(frame))) == format(frame)");
}

void read_all(const std::string& text, dynid::can::OnError on_error) {
  std::istringstream in(text);
  dynid::can::CandumpReader reader(in, "fuzz.log", on_error);
  dynid::can::Frame frame;
  std::size_t frames = 0;
  while (reader.next(frame)) {
    ++frames;
    round_trip(frame);
  }
  dynid::fuzz::expect(frames == reader.frame_count(), "frame_count() counts the frames read");
  dynid::fuzz::expect(reader.errors().size() <= dynid::can::CandumpReader::kMaxKeptErrors,
                      "at most kMaxKeptErrors errors kept");
  for (const auto& error : reader.errors()) (void)reader.describe(error);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  read_all(text, dynid::can::OnError::Continue);
  read_all(text, dynid::can::OnError::Stop);
  return 0;
}
