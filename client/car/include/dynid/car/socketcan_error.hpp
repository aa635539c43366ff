#pragma once
// SocketCanError: a SocketCAN operation the kernel refused, with everything needed to act on it.
//
// Contract: what() reads "SocketCAN <interface>: <operation> failed: <strerror> (<ERRNO NAME>)"
// followed, for the errors a car installation actually meets, by a hint: EAFNOSUPPORT (this
// kernel has no CAN: CONFIG_CAN / modules can, can-raw), ENODEV (no such CAN interface),
// ENETDOWN (interface down), EPERM/EACCES (permission). It is an InputError, so callers that
// already report bad input report this the same way; errno() and interface_name() let a caller
// tell the cases apart without parsing the text.
#include <string>
#include <string_view>

#include <dynid/error.hpp>

namespace dynid::car {

class SocketCanError : public InputError {
 public:
  SocketCanError(std::string_view interface_name, std::string_view operation, int error_number);

  int error_number() const { return errno_; }
  const std::string& interface_name() const { return interface_; }

 private:
  std::string interface_;
  int errno_;
};

/// "EAFNOSUPPORT" for EAFNOSUPPORT; "errno <n>" for a number glibc has no name for.
std::string errno_name(int error_number);

}  // namespace dynid::car
