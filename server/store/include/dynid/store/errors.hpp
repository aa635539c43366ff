#pragma once
// Errors of the durable store.
//
// Contract: malformed input (an unknown run, a conflicting announcement, a chunk that fails
// validation, a ledger mark that would fold twice) is dynid::InputError and changes no state.
// A failure of the storage itself is StoreError: its message names the store's location (a
// URI without its password), the operation and the engine's reason: SQLite's with its extended
// result code (code()), PostgreSQL's with its SQLSTATE in the message (code() is 0); a disk that
// is full reports SQLITE_FULL (PostgreSQL: SQLSTATE 53100). Data that is on disk but no longer what was written (a page that fails
// PRAGMA quick_check, a chunk or checkpoint whose checksum does not match) is CorruptionError,
// naming the file and, for a row, the vehicle/run/sequence it belongs to. A write that throws
// either has been rolled back: nothing half-written, and nothing may be acknowledged.
#include <stdexcept>
#include <string>

namespace dynid::store {

class StoreError : public std::runtime_error {
 public:
  StoreError(const std::string& message, int code) : std::runtime_error(message), code_(code) {}
  /// SQLite's extended result code (0 when the failure is not SQLite's: a checksum, PostgreSQL).
  int code() const { return code_; }

 private:
  int code_;
};

class CorruptionError : public StoreError {
 public:
  using StoreError::StoreError;
};

/// A write of a vehicle whose lease the store's holder does not hold (store.hpp, Leases): the
/// message names the vehicle, the holder and the lease as it stands; nothing was written. The
/// server must stop serving that vehicle.
class NotHolderError : public StoreError {
 public:
  explicit NotHolderError(const std::string& message) : StoreError(message, 0) {}
};

}  // namespace dynid::store
