#pragma once
// One CAN or CAN FD frame as it travels between the log readers, SocketCAN and the decoder.
//
// Contract: `id` holds 11 bits (extended == false) or 29 bits (extended == true), never flag
// bits; `length` <= 8 for classic CAN and <= 64 for CAN FD; bytes past `length` are zero.
// The interface name (e.g. "can0") is stored inline, without allocation, because the frame is
// copied in the hot path; it is at most 15 characters as in Linux's IFNAMSIZ.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace dynid::can {

class Frame {
 public:
  static constexpr std::size_t kMaxClassicData = 8;
  static constexpr std::size_t kMaxFdData = 64;
  static constexpr std::size_t kMaxInterfaceName = 15;
  static constexpr std::uint32_t kMaxStandardId = 0x7FFU;
  static constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFFU;
  // CAN FD flags as candump writes them after "##": bit-rate switch, error state indicator.
  static constexpr std::uint8_t kFdBrs = 0x1;
  static constexpr std::uint8_t kFdEsi = 0x2;

  double timestamp = 0.0;  // seconds (the log's clock; candump: since the epoch or boot)
  std::uint32_t id = 0;
  bool extended = false;
  bool fd = false;
  bool rtr = false;        // remote transmission request: no data
  std::uint8_t fd_flags = 0;
  std::uint8_t length = 0;  // payload bytes in use
  std::array<std::uint8_t, kMaxFdData> data{};

  std::span<const std::uint8_t> payload() const { return {data.data(), length}; }
  std::string_view interface_name() const { return {iface_.data(), iface_len_}; }
  // Returns false (and leaves the name unchanged) when `name` is longer than 15 characters.
  bool set_interface_name(std::string_view name);

 private:
  std::array<char, kMaxInterfaceName> iface_{};
  std::uint8_t iface_len_ = 0;
};

// The payload lengths a CAN FD frame can carry (DLC 0..15).
bool is_valid_fd_length(std::size_t length);

}  // namespace dynid::can
