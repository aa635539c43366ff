#pragma once
// DdsError: a Cyclone DDS call failed (not a bad sample: those are dynid::InputError).
//
// Contract: the message names the call and Cyclone's reason (dds_strretcode), e.g.
// "dds_create_reader(Chunk): Bad parameter". check() turns a negative return code into one.
#include <dds/dds.h>

#include <stdexcept>
#include <string>

namespace dynid::dds {

class DdsError : public std::runtime_error {
 public:
  DdsError(const std::string& call, dds_return_t code);
  dds_return_t code() const { return code_; }

 protected:
  /// A failure `what` explains in full (a subclass's own message), with Cyclone's code.
  DdsError(dds_return_t code, const std::string& what) : std::runtime_error(what), code_(code) {}

 private:
  dds_return_t code_;
};

/// Returns `result` when it is not negative; throws DdsError naming `call` otherwise.
dds_return_t check(dds_return_t result, const std::string& call);

}  // namespace dynid::dds
