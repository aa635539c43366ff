#pragma once
// LogReader: the frames of a recorded CAN log, whatever its format. Four formats are read:
// candump -l (candump.hpp), Vector ASC (asc.hpp), Vector BLF (blf.hpp), PEAK PCAN traces
// (trc.hpp) and ASAM MDF4 bus logs (mdf4_bus.hpp); open_log() picks the reader from the file's
// content (BLF starts with "LOGG", MDF4 with "MDF     " or, unfinalized, "UnFinMF "; a PCAN
// trace's first line is ";$FILEVERSION=" or its header comment names PCAN; an ASC file's first
// non-blank line is one of its header keywords; anything else is read as candump, whose reader
// then names the bad lines, and a replay refusing a file of mostly bad lines says what the file
// looks like: log_content.hpp).
//
// Contract (every reader): next() never throws for bad data. A bad line or object is counted
// (error_count()), the first kMaxKeptErrors are kept with where they are (a line number for the
// text formats, the byte offset of the object for BLF: describe() says which), and reading
// continues, or stops with OnError::Stop, at the n-th error (stop_after_errors) or once n bytes
// of the file are read (stop_after_bytes: what bounds a look at a file whatever it holds, e.g.
// one endless line). Only a file
// that cannot be opened, or is not a regular file (input/input_file.hpp), throws InputError
// naming it. Frames come out in file order with their timestamps in seconds on the log's clock;
// a format that stores the measurement start (ASC, BLF, TRC, MDF4) gives start + offset (see
// its header). bytes_consumed() is how far into the file the reader is (for progress).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iosfwd>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <dynid/can/frame.hpp>

namespace dynid::can {

struct LogError {
  std::size_t line = 0;  ///< line number (text formats) or byte offset of the object (BLF, MDF4)
  std::string reason;
};

enum class OnError { Continue, Stop };

enum class LogFormat { Candump, Asc, Blf, Trc, Mdf4 };

std::string_view log_format_name(LogFormat format);

class LogReader {
 public:
  static constexpr std::size_t kMaxKeptErrors = 1000;
  virtual ~LogReader() = default;

  /// The next good frame; false at the end of the input or after stopping on an error.
  virtual bool next(Frame& frame) = 0;
  /// Stop at the n-th error (counted from the start), whatever on_error says.
  void stop_after_errors(std::size_t n) { max_errors_ = n; }
  /// Stop once about n bytes of the input are read (a line or object in progress is cut there).
  void stop_after_bytes(std::uint64_t n) { max_bytes_ = n; }
  const std::vector<LogError>& errors() const { return errors_; }
  std::size_t error_count() const { return error_count_; }
  std::size_t frame_count() const { return frame_count_; }
  bool stopped() const { return stopped_; }
  const std::string& source() const { return source_; }
  /// "<source>:<line>: <reason>" (text formats) or "<source>: offset <n>: <reason>" (BLF, MDF4).
  virtual std::string describe(const LogError& error) const;
  virtual std::uint64_t bytes_consumed() const = 0;
  virtual LogFormat format() const = 0;

 protected:
  LogReader(std::string source, OnError on_error) : source_(std::move(source)), on_error_(on_error) {}
  /// Counts an error at `where`, keeps the first kMaxKeptErrors, stops as the contract says.
  void record_error(std::size_t where, std::string reason);
  /// Bytes left before stop_after_bytes' bound; at 0 the reader is stopped.
  std::uint64_t byte_budget();
  /// Opens a regular file (input/input_file.hpp), else InputError "<path>: ..." naming `what`.
  static std::unique_ptr<std::ifstream> open_file(const std::filesystem::path& path, std::string_view what);

  std::size_t frame_count_ = 0;
  bool stopped_ = false;

 private:
  std::string source_;
  OnError on_error_;
  std::vector<LogError> errors_;
  std::size_t error_count_ = 0;
  std::size_t max_errors_ = static_cast<std::size_t>(-1);
  std::uint64_t max_bytes_ = static_cast<std::uint64_t>(-1);
};

/// A log of text lines (candump, ASC, TRC). A line of more than max_line_bytes is no frame of any
/// format: it is one bad line ("line of <n> bytes ..."), whatever its length, and is skipped to
/// its end in pieces, so memory does not grow with it (a look at a file bounded by
/// stop_after_bytes stops inside an endless line). Blank lines are skipped.
class LineLogReader : public LogReader {
 public:
  bool next(Frame& frame) final;
  std::uint64_t bytes_consumed() const final { return bytes_; }
  std::size_t line_number() const { return line_; }

 protected:
  LineLogReader(std::istream& in, std::string source, OnError on_error, std::size_t max_line_bytes);
  LineLogReader(const std::filesystem::path& path, std::string_view what, OnError on_error,
                std::size_t max_line_bytes);
  /// One line (not blank): "" and is_frame when it is a frame (in `frame`), "" and not is_frame
  /// when it is no frame but good (a header, an event), else the reason it is bad.
  virtual std::string parse_line(std::string_view line, Frame& frame, bool& is_frame) = 0;

 private:
  bool read_line(bool& too_long);
  std::string skip_long_line();

  std::unique_ptr<std::ifstream> file_;
  std::istream* in_;
  std::size_t max_line_bytes_;
  std::string buffer_;
  std::size_t line_ = 0;
  std::uint64_t bytes_ = 0;
};

/// The format of the file at `path` by its first bytes (see above); throws InputError when it
/// cannot be read or is not a regular file.
LogFormat detect_log_format(const std::filesystem::path& path);

/// A reader of the right format for the file at `path`.
std::unique_ptr<LogReader> open_log(const std::filesystem::path& path, OnError on_error = OnError::Continue);

/// Seconds from a count of nanoseconds: the nearest double to the decimal value when the count
/// is whole microseconds (what parsing the same time from a candump log gives), else whole
/// seconds plus the fraction.
double seconds_from_ns(std::int64_t ns);

}  // namespace dynid::can
