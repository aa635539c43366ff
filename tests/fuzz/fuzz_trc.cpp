// Fuzz target: the PCAN trace reader (can/trc.hpp) on arbitrary bytes, with the format detection
// and the description of a file of no log format (can/log_content.hpp) on the same bytes as a
// file's head. The reader's contract (can/log_reader.hpp) is that it never throws for bad data,
// so any exception is a finding; every frame keeps can::Frame's contract and the counts add up
// (fuzz_log_check.hpp): a line is a frame, a skipped record or an error, never two of them.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "dynid/can/log_content.hpp"
#include "dynid/can/trc.hpp"
#include "fuzz_log_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const auto lines = static_cast<std::size_t>(std::count(bytes.begin(), bytes.end(), '\n')) + 1;
  for (const auto on_error : {dynid::can::OnError::Continue, dynid::can::OnError::Stop}) {
    std::istringstream in(bytes);
    dynid::can::TrcReader reader(in, "fuzz.trc", on_error);
    const std::size_t frames = dynid::fuzz::read_all(reader);
    dynid::fuzz::expect(frames + reader.skipped() + reader.error_count() <= lines,
                        "each line is a frame, a skipped record or an error");
    dynid::fuzz::expect(reader.bytes_consumed() <= bytes.size(),
                        "no more bytes consumed than given");
  }
  (void)dynid::can::looks_like_trc(bytes);
  const std::string description = dynid::can::describe_log_content(bytes);
  for (const char c : description)  // the file's bytes reach the message escaped
    dynid::fuzz::expect(c >= 0x20 && c < 0x7f, "the description is printable");
  return 0;
}
