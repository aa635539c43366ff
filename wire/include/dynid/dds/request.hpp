#pragma once
// Request and Reply: the engineers' request/reply pair (wire types Request, Reply).
//
// A client picks an id (e.g. "<user>@<host>/<pid>") and numbers its requests; the server's
// reply carries the same (client, correlation_id), so a client matches replies to requests
// and ignores the others'. `kind` and `arguments` are validated by the server; a refused
// request gets status kBadRequest and a readable error.
#include <cstdint>
#include <string>
#include <vector>

namespace dynid::dds {

struct RequestArgument {
  std::string name;
  std::string value;
};

struct Request {
  std::string client;
  std::uint64_t correlation_id = 0;
  std::string kind;
  std::vector<RequestArgument> arguments;
};

enum class ReplyStatus { kOk, kBadRequest, kNotFound, kFailed };

struct Reply {
  std::string client;
  std::uint64_t correlation_id = 0;
  ReplyStatus status = ReplyStatus::kOk;
  std::string error;           ///< readable reason when status != kOk
  std::string payload_format;  ///< e.g. "text/plain", "application/json"
  std::string payload;         ///< bytes
  /// The answering server's shard K of N; shard_count 0 when the server does not say (one
  /// server, or one older than the field). to_wire/from_wire refuse shard >= shard_count > 0.
  std::uint32_t shard = 0;
  std::uint32_t shard_count = 0;
};

}  // namespace dynid::dds
