#pragma once
// ShardReplies: the answers of several dynid-servers, one per shard, to one request that every
// server answers (vehicles, status), and how the CLI merges them (docs/DESIGN.md, Scale-out).
//
// Contract:
// - add() keeps the first reply of each shard (the client resends until all shards answered,
//   so a server may answer twice from its reply cache). The shard count N is learned from the
//   first reply; a reply with shard_count 0 (a server that does not say) counts as shard 0/1.
//   A reply naming another N than the first throws ShardMismatch naming both: the servers of
//   one domain were started with different --shard N, and merging their answers would hide
//   vehicles or show some twice.
// - complete() once every shard 0..N-1 answered; missing() lists the others.
// - failure(): the first (lowest-shard) reply whose status is not OK, if any. Every server
//   checks a request the same way, so a refusal from one is the refusal of all.
// - merged_vehicles(): the union of the shards' lists (JSON arrays of strings, as the server
//   writes with format=json), sorted; a vehicle listed by two shards is listed once.
//   merged_status(): one shard: its counters as they are; several:
//   {"shards":{"K/N":{counters},...},"missing":["K/N",...]}. Both throw InputError naming the
//   shard whose payload is not what it should be.
// - missing_note(): one sentence naming the shards that did not answer, for stderr.
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/dds/request.hpp"

namespace dynid::cli {

class ShardMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ShardReplies {
 public:
  /// True when the reply is the first of its shard (and kept).
  bool add(const dds::Reply& reply);
  bool empty() const { return replies_.empty(); }
  std::uint32_t count() const { return count_; }  ///< N, 0 before the first reply
  bool complete() const { return count_ != 0 && replies_.size() == count_; }
  std::vector<std::uint32_t> missing() const;
  const std::map<std::uint32_t, dds::Reply>& replies() const { return replies_; }
  std::optional<dds::Reply> failure() const;

 private:
  std::uint32_t count_ = 0;
  std::map<std::uint32_t, dds::Reply> replies_;  // by shard index
};

/// "K/N".
std::string shard_name(std::uint32_t index, std::uint32_t count);

std::vector<std::string> merged_vehicles(const ShardReplies& replies);
/// The vehicle list as `dynid vehicles` prints it: one per line, or a JSON array.
std::string render_vehicles(const std::vector<std::string>& vehicles, bool json);
std::string merged_status(const ShardReplies& replies);
/// `dynid status` for people: per shard (a heading when there are several) one line per
/// counter, with what it counts ("chunks stored durably ... 40"), and a line per shard that did
/// not answer. Counters this client does not know are printed by their JSON name. Servers on
/// one PostgreSQL store (leases) answer as shard 0/1 with "server" (its id) and "servers"
/// ([{"id", "vehicles"}]: who holds which vehicle): then a table follows the counters, one
/// line per server: its id, how many vehicles it holds, and which.
std::string status_text(const ShardReplies& replies);
/// E.g. "shard 1/2 did not answer within 10000 ms: its vehicles are not included" (`what`:
/// "vehicles"). Empty when nothing is missing.
std::string missing_note(const ShardReplies& replies, std::int64_t timeout_ms, const std::string& what);

}  // namespace dynid::cli
