#pragma once
// ServerCounters: what the server has accepted and refused since it started (this process).
//
// Every rejection of input (a malformed or invalid sample, a bad request) increments one of
// them, so "counted" in DESIGN.md's "Bad input" is observable: by the `status` request, in the
// log at shutdown, and in-process through Server::counters(). Lock-free; readers take a
// snapshot.
#include <atomic>
#include <cstdint>
#include <string>

namespace dynid::server {

struct CounterSnapshot {
  std::uint64_t announcements = 0;           ///< runs accepted (new or already known)
  std::uint64_t rejected_announcements = 0;
  std::uint64_t chunks_stored = 0;           ///< newly stored durably
  std::uint64_t chunks_duplicate = 0;        ///< already stored, same bytes: re-acknowledged
  std::uint64_t chunks_rejected = 0;         ///< malformed, invalid, conflicting, out of window
  std::uint64_t chunks_folded = 0;           ///< folded into accumulators by this process
  std::uint64_t chunks_replayed = 0;         ///< of those, read back from the store
  std::uint64_t checkpoints = 0;
  std::uint64_t estimates_published = 0;
  std::uint64_t requests = 0;
  std::uint64_t requests_rejected = 0;       ///< bad request or not found
  std::uint64_t not_owned = 0;               ///< samples of vehicles of other shards (or leased elsewhere), ignored
  std::uint64_t store_errors = 0;            ///< storage failures (nothing acknowledged)
  std::uint64_t requests_cancelled = 0;  ///< stopped computing: the client left, the server stops

  std::string to_json() const;
};

class ServerCounters {
 public:
  using Field = std::uint64_t CounterSnapshot::*;
  void add(Field field, std::uint64_t count = 1);
  CounterSnapshot snapshot() const;

 private:
  static constexpr int kFields = 14;
  static int slot(Field field);
  std::atomic<std::uint64_t> values_[kFields] = {};
};

}  // namespace dynid::server
