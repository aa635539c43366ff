#pragma once
// The CAN frames of an ASAM MDF4 bus log (mdf4.hpp reads the file), as a LogReader
// (log_reader.hpp: the error contract; an error's position is a byte offset in the file).
//
// Frames are the records of the channel groups called "CAN_DataFrame" (the ASAM bus logging
// layout that loggers such as the CANedge, CANape and IPEmotion write), read by the names of
// their channels: CAN_DataFrame.ID, .IDE (29-bit id; without an IDE channel, bit 31 of a 32-bit
// ID is the flag, as Vector writes it), .DLC, .DataLength (bytes; without it the DLC gives the
// length), .DataBytes (a fixed byte array, or a VLSD channel whose values are in an ##SD block
// or a VLSD channel group), .EDL (CAN FD), .BRS, .ESI and .BusChannel. Channels are numbered
// from 1: bus channel n is the interface "can<n-1>", as in blf.hpp and asc.hpp; without a
// BusChannel channel every frame is on "can0". Several CAN_DataFrame groups are merged in time
// order. Records of the groups CAN_ErrorFrame and CAN_RemoteFrame are skipped and counted
// (error_frames(), remote_frames()), as are those of other groups (LIN, ...: other_records()).
//
// Time: a frame's timestamp is the header's start time plus its master channel (seconds after
// its conversion), summed in whole nanoseconds, as blf.hpp does.
//
// Reading: the file is read whole at the first next() (links point anywhere in it); a
// structural error then (Mdf4Error) is one error at its offset and ends the reading, as does a
// record that cannot be read; a bad frame (an id or length out of range) is an error and is
// skipped. notes() says what was recovered from an unfinalized file, where a record whose data
// bytes (a VLSD value written after it) are missing is dropped, not an error: the logger lost
// power between the two. bytes_consumed() is the
// share of the file's records given so far, in bytes, so stop_after_bytes bounds the frames
// given (the file itself is read whole).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <dynid/can/log_reader.hpp>
#include <dynid/can/mdf4.hpp>

namespace dynid::can {

class Mdf4BusReader final : public LogReader {
 public:
  explicit Mdf4BusReader(const std::filesystem::path& path, OnError on_error = OnError::Continue);
  /// From bytes in memory (tests, fuzzing).
  Mdf4BusReader(std::vector<std::uint8_t> bytes, std::string source,
                OnError on_error = OnError::Continue);
  ~Mdf4BusReader() override;

  bool next(Frame& frame) override;
  std::string describe(const LogError& error) const override;
  std::uint64_t bytes_consumed() const override;
  LogFormat format() const override { return LogFormat::Mdf4; }

  /// What was recovered from an unfinalized file (empty for a finalized one).
  std::vector<std::string> notes() const;
  std::uint64_t error_frames() const { return error_frames_; }
  std::uint64_t remote_frames() const { return remote_frames_; }
  std::uint64_t other_records() const { return other_records_; }

 private:
  struct Cursor;
  void load();
  void open_groups();
  bool advance(Cursor& cursor);
  bool decode(Cursor& cursor, std::size_t k, Frame& frame);

  std::filesystem::path path_;
  std::vector<std::uint8_t> bytes_;
  std::unique_ptr<Mdf4File> file_;
  std::vector<std::unique_ptr<Cursor>> cursors_;
  bool loaded_ = false;
  bool ended_ = false;
  std::uint64_t total_records_ = 0;
  std::uint64_t given_records_ = 0;
  std::uint64_t error_frames_ = 0;
  std::uint64_t remote_frames_ = 0;
  std::uint64_t other_records_ = 0;
  std::uint64_t unwritten_ = 0;  // unfinalized: records whose VLSD data bytes are missing
};

}  // namespace dynid::can
