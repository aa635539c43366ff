// Fuzz target: the Vector log readers (can/asc.hpp, can/blf.hpp) on arbitrary bytes. Their
// contract (can/log_reader.hpp) is that they never throw for bad data, so any exception is a
// finding; every frame they return must keep can::Frame's contract and the counts must add up
// (fuzz_log_check.hpp).
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "dynid/can/asc.hpp"
#include "dynid/can/blf.hpp"
#include "fuzz_log_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (const auto on_error : {dynid::can::OnError::Continue, dynid::can::OnError::Stop}) {
    std::istringstream asc(bytes);
    dynid::can::AscReader a(asc, "fuzz.asc", on_error);
    dynid::fuzz::read_all(a);
    std::istringstream blf(bytes);
    dynid::can::BlfReader b(blf, "fuzz.blf", on_error);
    dynid::fuzz::read_all(b);
  }
  return 0;
}
