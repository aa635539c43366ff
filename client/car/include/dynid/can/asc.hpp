#pragma once
// Vector ASC logs (ASCII, as CANalyzer/CANoe and python-can write them), read as a LogReader
// (log_reader.hpp: the error contract).
//
// Read: the header lines "date <date>", "base hex|dec  timestamps absolute|relative",
// "[no] internal events logged", "// ..." comments, "Begin Triggerblock [<date>]" and
// "End TriggerBlock"; event lines "<time> <event>", of which these are frames:
//   <time> <ch> <id>[x] Rx|Tx d <dlc> <bytes...> [more fields]    classic CAN (x: 29-bit id)
//   <time> <ch> <id>[x] Rx|Tx r [<dlc>]                           remote frame
//   <time> CANFD <ch> Rx|Tx <id>[x] [<name>] <brs> <esi> <dlc> <length> <bytes...> [more fields]
// and these are known events that carry no frame, skipped: "Start of measurement", "<ch> Statistic:",
// "<ch> Chip status", "<ch> ErrorFrame" (counted as an error, as candump's error frames are).
// "base dec" reads ids and bytes as decimal. Any other line is an error naming its line.
//
// Time: "<time>" is seconds with up to 9 decimals from the measurement start ("timestamps
// absolute") or from the previous event ("timestamps relative"), summed in whole nanoseconds. The
// measurement start is the date of "Begin Triggerblock" (else of "date"), read as UTC with its
// millisecond resolution ("Thu Jan 01 12:53:28.584 PM 1970", 12- or 24-hour, English names); the
// frame's timestamp is start + time. Without a readable date the start is 0 (start_known() false).
// Channels are numbered from 1 in ASC: channel n is the interface "can<n-1>" (python-can's and
// SocketCAN's naming), so a profile's interfaces = ["can0"] selects ASC channel 1.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <dynid/can/log_reader.hpp>

namespace dynid::can {

/// Epoch nanoseconds (UTC) of an ASC date such as "Thu Jan 01 12:53:28.584 PM 1970", or nullopt.
std::optional<std::int64_t> parse_asc_date(std::string_view date);

class AscReader final : public LineLogReader {
 public:
  static constexpr std::size_t kMaxLineBytes = 4096;  // a CAN FD line with all its fields is ~600

  AscReader(std::istream& in, std::string source, OnError on_error = OnError::Continue)
      : LineLogReader(in, std::move(source), on_error, kMaxLineBytes) {}
  explicit AscReader(const std::filesystem::path& path, OnError on_error = OnError::Continue)
      : LineLogReader(path, "ASC log", on_error, kMaxLineBytes) {}

  LogFormat format() const override { return LogFormat::Asc; }
  bool start_known() const { return start_ns_.has_value(); }

 private:
  std::string parse_line(std::string_view line, Frame& frame, bool& is_frame) override;

  bool hex_ = true;
  bool relative_ = false;
  std::optional<std::int64_t> start_ns_;
  std::int64_t previous_ns_ = 0;  // time of the previous event (relative timestamps)
};

}  // namespace dynid::can
