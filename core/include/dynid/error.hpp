#pragma once
// Errors that cross the library's boundary.
//
// Contract: every input path (rows, serialized state, DBC files, CAN logs, profiles, DDS
// samples, requests) rejects what is malformed by throwing InputError with a message that
// names *what* was rejected, *where* (file:line, row/column, field) and *why*. A function that
// throws InputError leaves the object it was called on unchanged (strong guarantee), so a
// caller can count the rejection and carry on.
#include <stdexcept>
#include <string>

namespace dynid {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace dynid
