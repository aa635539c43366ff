#include <algorithm>
#include <dynid/can/frame.hpp>

namespace dynid::can {

bool Frame::set_interface_name(std::string_view name) {
  if (name.size() > kMaxInterfaceName) return false;
  iface_.fill('\0');
  std::copy(name.begin(), name.end(), iface_.begin());
  iface_len_ = static_cast<std::uint8_t>(name.size());
  return true;
}

bool is_valid_fd_length(std::size_t length) {
  return length <= 8 || length == 12 || length == 16 || length == 20 || length == 24 ||
         length == 32 || length == 48 || length == 64;
}

}  // namespace dynid::can
