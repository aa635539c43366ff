#include "dynid/car/socketcan_error.hpp"

#include <cerrno>
#include <cstring>

namespace dynid::car {
namespace {

// What to do about it, for the errors an installation meets; the errno text alone ("Address
// family not supported by protocol") does not say that the kernel lacks CAN.
std::string_view hint(int error_number) {
  switch (error_number) {
    case EAFNOSUPPORT:
      return ": this kernel has no SocketCAN support (needs CONFIG_CAN and the modules can and "
             "can-raw)";
    case EPROTONOSUPPORT:
      return ": the kernel has CAN but not CAN_RAW (load the module can-raw)";
    case ENODEV:
      return ": no such CAN interface (see 'ip link'; a virtual one: 'ip link add dev vcan0 "
             "type vcan')";
    case ENETDOWN:
      return ": the interface is down ('ip link set up <interface>')";
    case EPERM:
    case EACCES:
      return ": permission denied (run as a user allowed to open raw CAN sockets)";
    default:
      return "";
  }
}

std::string message(std::string_view interface_name, std::string_view operation,
                    int error_number) {
  std::string out = "SocketCAN ";
  out.append(interface_name.empty() ? "<no interface>" : interface_name);
  out.append(": ").append(operation).append(" failed: ");
  out.append(std::strerror(error_number));
  out.append(" (").append(errno_name(error_number)).append(")");
  out.append(hint(error_number));
  return out;
}

}  // namespace

std::string errno_name(int error_number) {
  if (const char* name = strerrorname_np(error_number)) return name;
  return "errno " + std::to_string(error_number);
}

SocketCanError::SocketCanError(std::string_view interface_name, std::string_view operation,
                               int error_number)
    : InputError(message(interface_name, operation, error_number)),
      interface_(interface_name),
      errno_(error_number) {}

}  // namespace dynid::car
