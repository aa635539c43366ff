// Fuzz target: the ASAM MDF4 readers (can/mdf4.hpp, can/mdf4_bus.hpp) on arbitrary bytes.
// Mdf4BusReader keeps the LogReader contract (can/log_reader.hpp): it never throws for bad data,
// every frame keeps can::Frame's contract and the counts add up. Mdf4File may refuse the bytes
// with InputError (the documented outcome); what it parses must then be readable: every numeric
// channel of every channel group through read_signals, which either gives one value per record
// for each channel or throws InputError.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "dynid/can/mdf4.hpp"
#include "dynid/can/mdf4_bus.hpp"
#include "dynid/error.hpp"
#include "fuzz_check.hpp"

namespace {

using dynid::can::Frame;

void check_frame(const Frame& f) {
  dynid::fuzz::expect(f.id <= (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId),
                      "id within its kind");
  dynid::fuzz::expect(
      f.fd ? dynid::can::is_valid_fd_length(f.length) : f.length <= Frame::kMaxClassicData,
      "length within classic or FD limits");
  for (std::size_t i = f.length; i < f.data.size(); ++i)
    dynid::fuzz::expect(f.data[i] == 0, "bytes past the length are zero");
  dynid::fuzz::expect(!f.interface_name().empty(), "an interface name");
}

void read_bus(const std::vector<std::uint8_t>& bytes, dynid::can::OnError on_error) {
  dynid::can::Mdf4BusReader reader(bytes, "fuzz.mf4", on_error);
  Frame frame;
  std::size_t frames = 0;
  while (reader.next(frame)) {
    ++frames;
    check_frame(frame);
  }
  dynid::fuzz::expect(frames == reader.frame_count(), "frame_count() counts the frames read");
  dynid::fuzz::expect(reader.errors().size() <= dynid::can::LogReader::kMaxKeptErrors,
                      "at most kMaxKeptErrors kept");
  for (const auto& error : reader.errors()) (void)reader.describe(error);
  (void)reader.notes();
}

void read_signals(const std::vector<std::uint8_t>& bytes) {
  try {
    const dynid::can::Mdf4File file(bytes, "fuzz.mf4");
    for (std::size_t d = 0; d < file.data_groups().size(); ++d)
      for (std::size_t c = 0; c < file.data_groups()[d].groups.size(); ++c) {
        std::vector<std::string> names;
        for (const auto& channel : file.data_groups()[d].groups[c].channels)
          names.push_back(channel.name);
        try {
          const auto signals = file.read_signals(d, c, names);
          for (const auto& values : signals.values)
            dynid::fuzz::expect(values.size() == signals.time.size(),
                                "a value per record for each channel");
        } catch (const dynid::InputError&) {
          // a channel that is no number, or data that cannot be read: documented
        }
      }
  } catch (const dynid::InputError&) {
    // not an MDF4 file the reader can read: documented
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::uint8_t> bytes(data, data + size);
  read_bus(bytes, dynid::can::OnError::Continue);
  read_bus(bytes, dynid::can::OnError::Stop);
  read_signals(bytes);
  return 0;
}
