// Fuzz target: the Vector log readers (can/asc.hpp, can/blf.hpp) on arbitrary bytes. Their
// contract (can/log_reader.hpp) is that they never throw for bad data, so any exception is a
// finding; every frame they return must keep can::Frame's contract (id within its kind, length
// within classic or FD limits, bytes past the length zero), and the counts must add up.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "dynid/can/asc.hpp"
#include "dynid/can/blf.hpp"
#include "fuzz_check.hpp"

namespace {

void check_frame(const dynid::can::Frame& f) {
  using dynid::can::Frame;
  dynid::fuzz::expect(f.id <= (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId), "id within its kind");
  dynid::fuzz::expect(f.fd ? dynid::can::is_valid_fd_length(f.length) : f.length <= Frame::kMaxClassicData,
                      "length within classic or FD limits");
  for (std::size_t i = f.length; i < f.data.size(); ++i)
    dynid::fuzz::expect(f.rtr || f.data[i] == 0, "bytes past the length are zero");
  dynid::fuzz::expect(!f.interface_name().empty(), "an interface name");
}

void read_all(dynid::can::LogReader& reader) {
  dynid::can::Frame frame;
  std::size_t frames = 0;
  while (reader.next(frame)) {
    ++frames;
    check_frame(frame);
  }
  dynid::fuzz::expect(frames == reader.frame_count(), "frame_count() counts the frames read");
  dynid::fuzz::expect(reader.errors().size() <= dynid::can::LogReader::kMaxKeptErrors, "at most kMaxKeptErrors kept");
  for (const auto& error : reader.errors()) (void)reader.describe(error);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (const auto on_error : {dynid::can::OnError::Continue, dynid::can::OnError::Stop}) {
    std::istringstream asc(bytes);
    dynid::can::AscReader a(asc, "fuzz.asc", on_error);
    read_all(a);
    std::istringstream blf(bytes);
    dynid::can::BlfReader b(blf, "fuzz.blf", on_error);
    read_all(b);
  }
  return 0;
}
