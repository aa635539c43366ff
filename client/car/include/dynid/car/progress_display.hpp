#pragma once
// ProgressDisplay: dynid-car's progress on stderr. On a terminal it is one line rewritten in
// place (at most every `tty_interval`); otherwise (a log file, a pipe, the demo's output) it is a
// plain line every `line_interval`, so logs stay readable and small.
//
// Contract: update() shows the latest status line (subject to the intervals; `force` shows it
// now). message() prints a line of its own without tearing the status line: on a terminal it
// clears the status line, prints the message and redraws the status. finish() ends the status
// line (a final newline on a terminal). log_sink() routes spdlog's messages through message().
// Thread-safe (spdlog may log from any thread).
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>

#include <spdlog/sinks/sink.h>

#include "dynid/car/delivery.hpp"
#include "dynid/car/replay.hpp"

namespace dynid::car {

class ProgressDisplay {
 public:
  ProgressDisplay(std::FILE* out, bool terminal,
                  std::chrono::milliseconds tty_interval = std::chrono::milliseconds(200),
                  std::chrono::milliseconds line_interval = std::chrono::milliseconds(5000));

  void update(const std::string& status, bool force = false);
  void message(const std::string& text);
  void finish();
  bool terminal() const { return terminal_; }

  /// An spdlog sink that writes through message().
  std::shared_ptr<spdlog::sinks::sink> log_sink();

 private:
  void draw_locked();

  std::FILE* out_;
  bool terminal_;
  std::chrono::milliseconds interval_;
  std::chrono::steady_clock::time_point last_;
  bool shown_once_ = false;
  std::string status_;
  bool on_screen_ = false;  // a terminal status line is drawn and not ended
  std::mutex mutex_;
};

/// "replay 57.3 % of can.log | 12.0 s of log | frames 123456 | chunks 40: sent 40, acked 38,
/// resent 0 | spool 2 chunks, 0.1 MiB"; for a live source (fraction < 0) the first part is just
/// `source` ("live can0").
std::string format_progress(const std::string& source, const ReplayProgress& replay,
                            const DeliveryStats& delivery, std::size_t pending,
                            std::uint64_t spool_bytes);

}  // namespace dynid::car
