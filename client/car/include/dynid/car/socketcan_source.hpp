#pragma once
// SocketCanSource: the live FrameSource, one CAN_RAW socket bound to one interface ("can0").
//
// Contract:
// - The constructor opens the socket, enables CAN FD frames (CAN_RAW_FD_FRAMES), kernel receive
//   timestamps (SO_TIMESTAMPNS), the kernel's drop counter (SO_RXQ_OVFL), error frames (so they
//   can be counted) and the filters, then binds. Any refusal throws SocketCanError naming the
//   interface, the call and errno (EAFNOSUPPORT on a kernel without CAN, ENODEV for an unknown
//   or non-CAN interface); an invalid name or filter throws InputError before any system call.
// - next() returns Frame with a classic or FD, 11- or 29-bit, data or remote frame; timestamp is
//   the kernel's receive time (CLOCK_REALTIME, seconds since the epoch, as candump -l writes);
//   the interface name is the bound interface. Error frames are counted (error_frames(),
//   bad_input()) and never returned. Timeout when nothing came within `timeout`; End after
//   request_stop() (immediately, also while next() waits in another thread) or close().
// - next() throws SocketCanError when the socket itself fails (interface removed or down).
// - next() and close() belong to one thread; request_stop() is async-signal-safe and may be
//   called from any thread or a SIGINT handler (it wakes a next() waiting in poll()).
// - Not copyable or movable (request_stop() may be called from a handler that holds a pointer).
#include <atomic>
#include <cmath>
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <dynid/can/frame.hpp>

#include "dynid/car/frame_source.hpp"
#include "dynid/car/socketcan_error.hpp"

namespace dynid::car {

/// A kernel receive time at the resolution of a candump -l log (whole microseconds; the kernel
/// gives nanoseconds): a log recorded beside the live reader then replays to the very same
/// chunks, bit for bit (the resampler interpolates, so a 0.4 us difference would change the
/// samples' low bits). A microsecond is far below a CAN frame's own duration (>= 47 us at
/// 1 Mbit/s), and a double of epoch seconds resolves only ~0.24 us anyway. micros / 1e6 is the
/// nearest double to the decimal the log holds, the value the log readers parse from it.
inline double live_timestamp(double kernel_seconds) {
  return static_cast<double>(std::llround(kernel_seconds * 1e6)) / 1e6;
}

/// Kernel-side acceptance filter: a frame passes when its extended flag equals `extended` and
/// (frame id & mask) == (id & mask); `inverted` passes exactly the frames that would not.
struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
  bool extended = false;
  bool inverted = false;

  static CanFilter exact(std::uint32_t frame_id, bool is_extended) {
    return {frame_id, is_extended ? can::Frame::kMaxExtendedId : can::Frame::kMaxStandardId,
            is_extended, false};
  }
};

struct SocketCanOptions {
  /// Empty: every frame. Otherwise a frame passes when any filter passes it.
  std::vector<CanFilter> filters;
  /// Kernel receive buffer in bytes (SO_RCVBUF); 0 keeps the system default. A bigger buffer
  /// rides out scheduling hiccups on a busy bus; overflows are counted in dropped().
  int receive_buffer_bytes = 0;
};

class SocketCanSource final : public FrameSource {
 public:
  explicit SocketCanSource(std::string interface_name, const SocketCanOptions& options = {});
  ~SocketCanSource() override;
  SocketCanSource(const SocketCanSource&) = delete;
  SocketCanSource& operator=(const SocketCanSource&) = delete;

  NextStatus next(can::Frame& frame, std::chrono::milliseconds timeout) override;
  std::uint64_t bad_input() const override { return error_frames_ + malformed_; }
  std::string name() const override { return interface_; }

  /// Makes a pending or later next() return End. Async-signal-safe.
  void request_stop() noexcept;
  /// Closes the socket; next() returns End from then on.
  void close() noexcept;

  std::uint64_t frames() const { return frames_; }
  std::uint64_t error_frames() const { return error_frames_; }
  /// Frames the kernel dropped because the receive queue was full (SO_RXQ_OVFL), as last seen.
  std::uint64_t dropped() const { return dropped_; }

 private:
  enum class ReadResult { Frame, Skipped, WouldBlock };
  void configure(const SocketCanOptions& options);
  void bind_interface();
  ReadResult read_one(can::Frame& frame);
  bool wait_readable(std::chrono::steady_clock::time_point deadline);

  std::string interface_;
  int socket_ = -1;
  int stop_event_ = -1;  // eventfd: wakes a poll() in progress when request_stop() is called
  std::atomic<bool> stop_{false};
  std::uint64_t frames_ = 0;
  std::uint64_t error_frames_ = 0;
  std::uint64_t malformed_ = 0;  // reads of a size that is neither CAN_MTU nor CANFD_MTU
  std::uint64_t dropped_ = 0;
};

}  // namespace dynid::car
