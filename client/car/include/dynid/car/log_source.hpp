#pragma once
// LogSource: a FrameSource over recorded CAN logs of any format can::open_log() reads (candump
// -l, Vector ASC, Vector BLF, PCAN trace, ASAM MDF4: can/log_reader.hpp picks it from each file's
// content), the replay path of dynid-car --replay.
//
// Several files (the splits of one recording a logger writes, or logs of several buses) are one
// source: their frames are merged in time order, each file read as it goes (a file's frames
// keep their order; among the files the one whose next frame is earliest gives it, the first
// file on a tie).
//
// Contract: as CandumpSource's (candump_source.hpp): a bad line or object is counted
// (bad_input(), the first ones kept in errors() with their line or byte offset) and skipped, never
// returned and never fatal; fraction_done() is the share of the files' bytes consumed; opening a
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
  /// max_bad, max_bytes: each file ends at that many bad lines or objects, or once it has read
  /// about that many bytes (a bounded look at a file, whatever it holds).
  explicit LogSource(const std::filesystem::path& path,
                     std::size_t max_bad = static_cast<std::size_t>(-1),
                     std::uint64_t max_bytes = static_cast<std::uint64_t>(-1));
  /// The files merged in time order (at least one).
  explicit LogSource(const std::vector<std::filesystem::path>& paths,
                     std::size_t max_bad = static_cast<std::size_t>(-1),
                     std::uint64_t max_bytes = static_cast<std::uint64_t>(-1));

  NextStatus next(can::Frame& frame, std::chrono::milliseconds timeout) override;
  std::uint64_t bad_input() const override;
  double fraction_done() const override;
  /// The file's name; for several files the first one's and how many follow ("a.MF4 (+1)").
  std::string name() const override;

  /// The first file's format.
  can::LogFormat format() const { return inputs_.front().reader->format(); }
  /// "<file>:<line>: <reason>" or "<file>: offset <n>: <reason>" for the first bad ones.
  std::vector<std::string> errors() const;
  /// What the readers recovered from their files (MDF4: unfinalized files), "<file>: <note>".
  std::vector<std::string> notes() const;

 private:
  struct Input {
    std::unique_ptr<can::LogReader> reader;
    std::uintmax_t size = 0;
    can::Frame pending;
    bool has = false;
  };
  std::vector<Input> inputs_;
  bool started_ = false;
};

}  // namespace dynid::car
