#pragma once
// Shard: which vehicles this server owns when several servers share one DDS domain
// (docs/DESIGN.md, "Scale-out").
//
// Contract:
// - A server with shard K/N owns vehicle v iff fnv1a64(v) mod N == K: every vehicle has
//   exactly one owner among servers 0/N .. (N-1)/N. FNV-1a (64-bit, over the id's bytes as
//   sent on the wire) is used, not std::hash, because every server and client, possibly built
//   by another compiler or for another machine, must agree on the partition of the vehicle space.
// - The owner alone stores, acknowledges, folds and publishes a vehicle's runs and answers the
//   requests that name it; other servers drop its samples (counted as not_owned).
// - N is fixed for a deployment: there is no rebalancing. A vehicle's runs live in its owner's
//   store, so a server refuses to start on a store holding vehicles it does not own
//   (foreign_vehicles()).
// - parse("K/N") throws InputError unless K and N are decimal and 0 <= K < N.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::server {

/// 64-bit FNV-1a of the bytes of `text` (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
std::uint64_t fnv1a64(std::string_view text);

struct Shard {
  std::uint32_t index = 0;
  std::uint32_t count = 1;

  /// The shard index that owns `vehicle` among `count` shards.
  static std::uint32_t owner_of(std::string_view vehicle, std::uint32_t count) {
    return static_cast<std::uint32_t>(fnv1a64(vehicle) % count);
  }
  bool owns(std::string_view vehicle) const { return owner_of(vehicle, count) == index; }
  /// The vehicles of `vehicles` that another shard owns, in their order.
  std::vector<std::string> foreign_vehicles(const std::vector<std::string>& vehicles) const;
  std::string to_string() const { return std::to_string(index) + "/" + std::to_string(count); }
  static Shard parse(std::string_view text);
};

}  // namespace dynid::server
