#pragma once
// LogSource: a FrameSource over a recorded CAN log of any format can::open_log() reads (candump
// -l, Vector ASC, Vector BLF, PCAN trace: can/log_reader.hpp picks it from the file's content), the
// replay path of dynid-car --replay.
//
// Contract: as CandumpSource's (candump_source.hpp): a bad line or object is counted
// (bad_input(), the first ones kept in errors() with their line or byte offset) and skipped, never
// returned and never fatal; fraction_done() is the share of the file's bytes consumed; opening a
// missing or unreadable file, or one that is not a regular file, throws InputError naming it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <dynid/can/log_reader.hpp>

#include "dynid/car/frame_source.hpp"

namespace dynid::car {

class LogSource final : public FrameSource {
 public:
  /// max_bad, max_bytes: the source ends at that many bad lines or objects, or once it has read
  /// about that many bytes (a bounded look at a file, whatever it holds).
  explicit LogSource(const std::filesystem::path& path,
                     std::size_t max_bad = static_cast<std::size_t>(-1),
                     std::uint64_t max_bytes = static_cast<std::uint64_t>(-1));

  NextStatus next(can::Frame& frame, std::chrono::milliseconds timeout) override;
  std::uint64_t bad_input() const override { return reader_->error_count(); }
  double fraction_done() const override;
  std::string name() const override { return reader_->source(); }

  can::LogFormat format() const { return reader_->format(); }
  /// "<file>:<line>: <reason>" or "<file>: offset <n>: <reason>" for the first bad ones.
  std::vector<std::string> errors() const;

 private:
  std::uintmax_t size_ = 0;
  std::unique_ptr<can::LogReader> reader_;
  bool ended_ = false;
};

}  // namespace dynid::car
