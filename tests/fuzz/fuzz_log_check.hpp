#pragma once
// The log readers' fuzz properties (fuzz_vector_logs, fuzz_trc): every frame keeps can::Frame's
// contract (id within its kind, length within classic or FD limits, bytes past the length zero,
// an interface name) and the counts add up.
#include <cstddef>

#include "dynid/can/log_reader.hpp"
#include "fuzz_check.hpp"

namespace dynid::fuzz {

inline void check_frame(const dynid::can::Frame& f) {
  using dynid::can::Frame;
  expect(f.id <= (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId),
         "id within its kind");
  expect(f.fd ? dynid::can::is_valid_fd_length(f.length) : f.length <= Frame::kMaxClassicData,
         "length within classic or FD limits");
  for (std::size_t i = f.length; i < f.data.size(); ++i)
    expect(f.rtr || f.data[i] == 0, "bytes past the length are zero");
  expect(!f.interface_name().empty(), "an interface name");
}

/// Reads the whole log, checking every frame; returns the count of frames.
inline std::size_t read_all(dynid::can::LogReader& reader) {
  dynid::can::Frame frame;
  std::size_t frames = 0;
  while (reader.next(frame)) {
    ++frames;
    check_frame(frame);
  }
  expect(frames == reader.frame_count(), "frame_count() counts the frames read");
  expect(reader.errors().size() <= dynid::can::LogReader::kMaxKeptErrors,
         "at most kMaxKeptErrors kept");
  for (const auto& error : reader.errors()) (void)reader.describe(error);
  return frames;
}

}  // namespace dynid::fuzz
