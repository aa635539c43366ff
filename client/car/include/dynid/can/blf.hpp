#pragma once
// Vector BLF logs (binary logging format, as CANoe/CANalyzer and python-can write them), read as
// a LogReader (log_reader.hpp: the error contract; an error's position is a byte offset).
//
// Layout read: the file header ("LOGG", its size at byte 4, the measurement start as a Windows
// SYSTEMTIME at byte 40: year, month, weekday, day, hour, minute, second, millisecond, 16 bits
// each), then objects, each "LOBJ", header size (16 bits), header version (16 bits), object size
// and object type (32 bits each). LOG_CONTAINER objects (type 10) hold further objects, stored
// (method 0) or zlib-compressed (method 2); an object may continue in the next container.
// Object header version 1 (flags, client index, object version, 64-bit timestamp) and 2 (flags,
// timestamp status, object version, timestamp, original timestamp) are read; the flags give the
// timestamp's unit: 1 = 10 us, 2 = 1 ns. Frames are CAN_MESSAGE (1) and CAN_MESSAGE2 (86)
// (channel, flags: 0x80 remote, dlc, id with bit 31 = 29-bit, 8 bytes) and CAN_FD_MESSAGE (100)
// (channel, flags, dlc, id, frame length, bit count, FD flags: 1 EDL, 2 BRS, 4 ESI, valid bytes,
// 64 bytes; without EDL it is a classic frame). Other object types (markers, statistics, LIN,
// error frames, CAN_FD_MESSAGE_64) are skipped and counted in skipped_objects(); CAN_ERROR_EXT
// (73) counts as an error, as candump's error frames do. Objects are found after 0..7 zero
// padding bytes (writers pad differently).
//
// Time: the frame's timestamp is the measurement start (SYSTEMTIME read as UTC; an all-zero
// SYSTEMTIME, which python-can writes for times before 1990, is start 0: start_known() false)
// plus the object's timestamp, summed in whole nanoseconds. Channels are numbered from 1: channel
// n is the interface "can<n-1>", as in asc.hpp.
//
// Bounds: a container or object larger than kMaxObjectBytes, a container whose data does not
// inflate to its stated size, or a file that ends inside an object is an error at its offset,
// and reading stops there (the rest of a binary file cannot be resynchronised).
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <dynid/can/log_reader.hpp>

namespace dynid::can {

class BlfReader final : public LogReader {
 public:
  static constexpr std::uint32_t kMaxObjectBytes = 64u << 20;

  BlfReader(std::istream& in, std::string source, OnError on_error = OnError::Continue);
  explicit BlfReader(const std::filesystem::path& path, OnError on_error = OnError::Continue);

  bool next(Frame& frame) override;
  std::string describe(const LogError& error) const override;
  std::uint64_t bytes_consumed() const override { return offset_; }
  LogFormat format() const override { return LogFormat::Blf; }

  bool start_known() const { return start_ns_ != 0; }
  std::uint64_t skipped_objects() const { return skipped_; }

 private:
  void read_header();
  // Refills inner_ from the next top-level object; false at the end or after a fatal error.
  bool next_container();
  // One inner object from inner_ at inner_pos_: 1 = a frame in `frame`, 0 = no frame (skipped,
  // or an error recorded), -1 = the object continues in the next container.
  int parse_inner(Frame& frame);
  void add_error(std::uint64_t offset, std::string reason, bool fatal = false);
  bool read_bytes(void* out, std::size_t n);

  std::unique_ptr<std::ifstream> file_;
  std::istream* in_;
  std::uint64_t skipped_ = 0;
  bool header_read_ = false;
  bool ended_ = false;
  std::int64_t start_ns_ = 0;
  std::uint64_t offset_ = 0;            // bytes of the file consumed
  std::vector<std::uint8_t> inner_;     // the objects of the current container(s)
  std::size_t inner_pos_ = 0;
  std::uint64_t container_offset_ = 0;  // file offset of the container inner_ came from
};

}  // namespace dynid::can
