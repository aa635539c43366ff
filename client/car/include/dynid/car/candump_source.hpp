#pragma once
// CandumpSource: a FrameSource over a candump -l log file (the replay path).
//
// Contract: wraps can::CandumpReader in OnError::Continue mode, so a bad line is counted
// (bad_input(), with the first ones kept in errors()) and skipped, never returned and never
// fatal. fraction_done() is the share of the file's bytes consumed. Opening a missing or
// unreadable file, or one that is not a regular file (FIFO, directory, device:
// input/input_file.hpp), throws InputError naming it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <dynid/can/candump.hpp>

#include "dynid/car/frame_source.hpp"

namespace dynid::car {

class CandumpSource final : public FrameSource {
 public:
  /// max_bad_lines: the source ends at that many bad lines (CandumpReader::stop_after_errors).
  explicit CandumpSource(const std::filesystem::path& path,
                         std::size_t max_bad_lines = static_cast<std::size_t>(-1));

  NextStatus next(can::Frame& frame, std::chrono::milliseconds timeout) override;
  std::uint64_t bad_input() const override { return reader_.error_count(); }
  double fraction_done() const override;
  std::string name() const override { return reader_.source(); }

  /// "<file>:<line>: <reason>" for the first bad lines (at most CandumpReader::kMaxKeptErrors).
  std::vector<std::string> errors() const;

 private:
  mutable std::ifstream file_;  // tellg() for progress is not const
  std::uintmax_t size_ = 0;
  can::CandumpReader reader_;
  bool ended_ = false;
};

}  // namespace dynid::car
