#pragma once
// candump log files ("candump -l" format, replayed by canplayer).
//
// Line format: "(<seconds>.<fraction>) <interface> <frame>" where <frame> is
//   123#0011223344556677   classic CAN, 3 hex digits = 11-bit id, 8 digits = 29-bit id
//   123##<flags><data>     CAN FD: one hex nibble of flags (1 = BRS, 2 = ESI), up to 64 bytes
//   123#R  or 123#R<dlc>   remote request (no data)
//   123#                   empty payload
// Data bytes may be separated by '.'. Blank lines are skipped. A direction after the frame, " R"
// (received) or " T" (sent), as python-can writes it, is allowed and ignored.
//
// Contract: the reader never throws for a bad line. It records the line number and reason,
// counts it, and by default continues with the next line; with OnError::Stop it stops at the
// first bad line (next() returns false and stopped() is true). Only the first
// kMaxKeptErrors errors are kept in errors(); error_count() counts all of them. A line of
// more than kMaxLineBytes is one bad line whatever its length, skipped to its end in pieces, so a
// file without newlines (a sparse file, a device's zeros) is read in bounded memory.
// stop_after_errors(n) stops the reader (as OnError::Stop does) at its n-th error, and
// stop_after_bytes(n) once it has read about n bytes: a look at the start of a file is bounded
// by both, whatever the file holds. Opening a path that is not a regular file
// (FIFO, directory, device) throws InputError naming it (input/input_file.hpp).
#include <cstddef>
#include <dynid/can/frame.hpp>
#include <dynid/can/log_reader.hpp>
#include <filesystem>
#include <fstream>
#include <iosfwd>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::can {

// Parses one log line into `frame`. Returns "" on success, else the reason the line is bad
// (`frame` is then unspecified).
std::string parse_candump_line(std::string_view line, Frame& frame);

// One line in candump -l format, without the newline. Throws InputError for a frame that
// cannot be written (negative, non-finite or too large timestamp (>= 9.2e12 s: its microsecond
// count would overflow), empty interface name, id too large
// for its kind, classic length > 8, FD length not a valid FD length).
std::string format_candump_line(const Frame& frame);

class CandumpReader final : public LineLogReader {
 public:
  /// Far beyond the longest candump line (a 64-byte FD frame with dots is under 300 bytes).
  static constexpr std::size_t kMaxLineBytes = 1024;

  // Reads from `in`, which must outlive the reader; `source` names it in messages.
  CandumpReader(std::istream& in, std::string source, OnError on_error = OnError::Continue)
      : LineLogReader(in, std::move(source), on_error, kMaxLineBytes) {}
  // Opens a file; throws InputError if it cannot be opened.
  explicit CandumpReader(const std::filesystem::path& path, OnError on_error = OnError::Continue)
      : LineLogReader(path, "candump log", on_error, kMaxLineBytes) {}

  LogFormat format() const override { return LogFormat::Candump; }

 private:
  std::string parse_line(std::string_view line, Frame& frame, bool& is_frame) override;
};

class CandumpWriter {
 public:
  explicit CandumpWriter(std::ostream& out) : out_(out) {}
  // Throws InputError (see format_candump_line); nothing is written then.
  void write(const Frame& frame);

 private:
  std::ostream& out_;
};

}  // namespace dynid::can
