#pragma once
// Shard: which vehicles this server owns when several servers share one DDS domain
// (DESIGN.md, "DDS interface": each takes the vehicles of its shard).
//
// Contract: a server with shard K/N owns vehicle v iff fnv1a64(v) mod N == K. FNV-1a is used,
// not std::hash, because every server process (possibly built by another compiler) must agree
// on the partition of the vehicle space. parse("K/N") throws InputError unless 0 <= K < N.
// Scale-out itself (a shared store, rebalancing) is a later issue; this is the hook.
#include <cstdint>
#include <string>
#include <string_view>

namespace dynid::server {

/// 64-bit FNV-1a of the bytes of `text`.
std::uint64_t fnv1a64(std::string_view text);

struct Shard {
  std::uint32_t index = 0;
  std::uint32_t count = 1;

  bool owns(std::string_view vehicle) const { return fnv1a64(vehicle) % count == index; }
  /// The first shard answers requests that name no vehicle (e.g. "vehicles").
  bool answers_fleet_requests() const { return index == 0; }
  std::string to_string() const { return std::to_string(index) + "/" + std::to_string(count); }
  static Shard parse(std::string_view text);
};

}  // namespace dynid::server
