#include <dynid/can/log_reader.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>

#include <dynid/can/asc.hpp>
#include <dynid/can/blf.hpp>
#include <dynid/can/candump.hpp>
#include <dynid/can/mdf4_bus.hpp>
#include <dynid/can/trc.hpp>
#include <dynid/error.hpp>
#include <dynid/input/input_file.hpp>

#include "log_text.hpp"

namespace dynid::can {

std::string_view log_format_name(LogFormat format) {
  switch (format) {
    case LogFormat::Candump: return "candump";
    case LogFormat::Asc: return "Vector ASC";
    case LogFormat::Blf: return "Vector BLF";
    case LogFormat::Mdf4:
      return "ASAM MDF4";
    case LogFormat::Trc:
      return "PCAN trace";
  }
  return "?";
}

LogFormat detect_log_format(const std::filesystem::path& path) {
  input::check_input_file(path, "CAN log");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open the CAN log");
  char head[4096];
  in.read(head, sizeof head);
  const auto n = static_cast<std::size_t>(in.gcount());
  if (n >= 4 && std::memcmp(head, "LOGG", 4) == 0) return LogFormat::Blf;
  if (n >= 8 && (std::memcmp(head, "MDF     ", 8) == 0 || std::memcmp(head, "UnFinMF ", 8) == 0))
    return LogFormat::Mdf4;
  if (looks_like_trc(std::string_view(head, n))) return LogFormat::Trc;
  // The first non-blank line of an ASC file is one of its header keywords.
  std::size_t i = 0;
  while (i < n && (head[i] == ' ' || head[i] == '\t' || head[i] == '\r' || head[i] == '\n')) ++i;
  const std::string_view rest(head + i, n - i);
  for (const std::string_view keyword : {"date ", "base ", "Begin Triggerblock", "// version", "internal events",
                                         "no internal events"})
    if (rest.substr(0, keyword.size()) == keyword) return LogFormat::Asc;
  return LogFormat::Candump;
}

std::unique_ptr<LogReader> open_log(const std::filesystem::path& path, OnError on_error) {
  switch (detect_log_format(path)) {
    case LogFormat::Blf: return std::make_unique<BlfReader>(path, on_error);
    case LogFormat::Asc: return std::make_unique<AscReader>(path, on_error);
    case LogFormat::Mdf4:
      return std::make_unique<Mdf4BusReader>(path, on_error);
    case LogFormat::Trc:
      return std::make_unique<TrcReader>(path, on_error);
    case LogFormat::Candump: break;
  }
  return std::make_unique<CandumpReader>(path, on_error);
}

std::string LogReader::describe(const LogError& error) const {
  return source_ + ":" + std::to_string(error.line) + ": " + error.reason;
}

void LogReader::record_error(std::size_t where, std::string reason) {
  ++error_count_;
  if (errors_.size() < kMaxKeptErrors) errors_.push_back(LogError{where, std::move(reason)});
  stopped_ = stopped_ || on_error_ == OnError::Stop || error_count_ >= max_errors_;
}

std::uint64_t LogReader::byte_budget() {
  const std::uint64_t read = bytes_consumed();
  if (read < max_bytes_) return max_bytes_ - read;
  stopped_ = true;
  return 0;
}

// Checked before opening: opening a FIFO would block until a writer appears.
std::unique_ptr<std::ifstream> LogReader::open_file(const std::filesystem::path& path, std::string_view what) {
  input::check_input_file(path, what);
  auto file = std::make_unique<std::ifstream>(path, std::ios::binary);
  if (!*file) throw InputError(path.string() + ": cannot open the " + std::string(what));
  return file;
}

LineLogReader::LineLogReader(std::istream& in, std::string source, OnError on_error, std::size_t max_line_bytes)
    : LogReader(std::move(source), on_error), in_(&in), max_line_bytes_(max_line_bytes) {}

LineLogReader::LineLogReader(const std::filesystem::path& path, std::string_view what, OnError on_error,
                             std::size_t max_line_bytes)
    : LogReader(path.filename().string(), on_error),
      file_(open_file(path, what)),
      in_(file_.get()),
      max_line_bytes_(max_line_bytes) {}

// getline with a bound: false at the end of the input. `too_long`: the line has
// more than max_line_bytes_ (its first piece is in buffer_, the rest still to read).
bool LineLogReader::read_line(bool& too_long) {
  buffer_.resize(max_line_bytes_ + 1);
  in_->getline(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  const auto got = static_cast<std::size_t>(in_->gcount());
  bytes_ += got;
  if (got == 0 && in_->fail()) return false;  // nothing left
  const bool delimited = !in_->fail() && !in_->eof();  // the '\n' was extracted and counted
  too_long = in_->fail() && !in_->eof();               // the buffer filled before a '\n'
  if (too_long) in_->clear();
  buffer_.resize(delimited ? got - 1 : got);
  return true;
}

// The rest of a too-long line, read up to its '\n' (or the end of the input, or the byte
// budget) in pieces and dropped: one bad line, whatever its length (a 100 MB line of junk in a
// good log once counted as 100,000 bad lines and outvoted the log's frames). Returns the reason.
std::string LineLogReader::skip_long_line() {
  constexpr std::streamsize kPiece = 1 << 16;
  std::uint64_t length = buffer_.size();
  std::vector<char> piece(static_cast<std::size_t>(kPiece));
  for (;;) {
    const std::uint64_t budget = byte_budget();
    if (budget == 0)
      return "line longer than " + std::to_string(max_line_bytes_) + " bytes (reading stopped " +
             std::to_string(length) + " bytes into it)";
    // getline stores a '\0' after at most size - 1 bytes: size - 1 is what may still be read.
    const auto size = static_cast<std::streamsize>(std::min<std::uint64_t>(budget, kPiece - 1) + 1);
    in_->getline(piece.data(), size);
    const auto got = static_cast<std::uint64_t>(in_->gcount());
    bytes_ += got;
    const bool delimited = !in_->fail() && !in_->eof();
    if (in_->fail() && !in_->eof()) {
      in_->clear();  // the piece filled before a '\n': the line goes on
      length += got;
      continue;
    }
    length += delimited ? got - 1 : got;  // else the line ends with the input
    return "line of " + std::to_string(length) + " bytes, longer than the " +
           std::to_string(max_line_bytes_) + " a line may have: skipped";
  }
}

bool LineLogReader::next(Frame& frame) {
  bool too_long = false;
  while (!stopped_ && byte_budget() > 0 && read_line(too_long)) {
    ++line_;
    if (!too_long && detail::trim(buffer_).empty()) continue;
    bool is_frame = false;
    std::string reason = too_long ? skip_long_line() : parse_line(buffer_, frame, is_frame);
    if (!reason.empty()) {
      record_error(line_, std::move(reason));
      continue;
    }
    if (is_frame) {
      ++frame_count_;
      return true;
    }
  }
  return false;
}

double seconds_from_ns(std::int64_t ns) {
  if (ns % 1000 == 0) return static_cast<double>(ns / 1000) / 1e6;
  return static_cast<double>(ns / 1'000'000'000LL) + static_cast<double>(ns % 1'000'000'000LL) / 1e9;
}

}  // namespace dynid::can
