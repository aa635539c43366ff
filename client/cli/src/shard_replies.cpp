#include "dynid/cli/shard_replies.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "dynid/dds/protocol.hpp"
#include "dynid/error.hpp"

namespace dynid::cli {

namespace {

using nlohmann::ordered_json;

std::string name_of(const dds::Reply& reply) { return shard_name(reply.shard, reply.shard_count); }

ordered_json parse_payload(const dds::Reply& reply, const std::string& what) {
  try {
    return ordered_json::parse(reply.payload);
  } catch (const ordered_json::parse_error& e) {
    throw InputError(what + " of shard " + name_of(reply) + ": not JSON (" + e.what() + ")");
  }
}

}  // namespace

std::string shard_name(std::uint32_t index, std::uint32_t count) {
  return std::to_string(index) + "/" + std::to_string(count);
}

bool ShardReplies::add(const dds::Reply& received) {
  dds::Reply reply = received;
  if (reply.shard_count == 0) {  // a server that does not say: the only one
    reply.shard = 0;
    reply.shard_count = 1;
  }
  if (count_ == 0) count_ = reply.shard_count;
  if (reply.shard_count != count_)
    throw ShardMismatch("the servers disagree on the number of shards: shard " + name_of(reply) +
                        " answered after shard " + name_of(replies_.begin()->second) +
                        "; start every dynid-server of the domain with the same --shard K/N");
  return replies_.emplace(reply.shard, std::move(reply)).second;
}

std::vector<std::uint32_t> ShardReplies::missing() const {
  std::vector<std::uint32_t> out;
  for (std::uint32_t k = 0; k < count_; ++k)
    if (!replies_.count(k)) out.push_back(k);
  return out;
}

std::optional<dds::Reply> ShardReplies::failure() const {
  for (const auto& [index, reply] : replies_)
    if (reply.status != dds::ReplyStatus::kOk) return reply;
  return std::nullopt;
}

std::vector<std::string> merged_vehicles(const ShardReplies& replies) {
  std::vector<std::string> out;
  for (const auto& [index, reply] : replies.replies()) {
    const auto list = parse_payload(reply, "vehicle list");
    if (!list.is_array()) throw InputError("vehicle list of shard " + name_of(reply) + ": not a JSON array");
    for (const auto& v : list) {
      if (!v.is_string())
        throw InputError("vehicle list of shard " + name_of(reply) + ": " + v.dump() + " is not a vehicle id");
      out.push_back(v.get<std::string>());
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string render_vehicles(const std::vector<std::string>& vehicles, bool json) {
  if (json) return ordered_json(vehicles).dump();
  std::string text;
  for (const auto& v : vehicles) text += v + "\n";
  return text;
}

std::string merged_status(const ShardReplies& replies) {
  if (replies.count() == 1 && replies.complete()) return replies.replies().begin()->second.payload;
  ordered_json out = {{"shards", ordered_json::object()}, {"missing", ordered_json::array()}};
  for (const auto& [index, reply] : replies.replies())
    out["shards"][name_of(reply)] = parse_payload(reply, "status");
  for (const auto index : replies.missing()) out["missing"].push_back(shard_name(index, replies.count()));
  return out.dump();
}

namespace {

std::string counter_lines(const ordered_json& counters, const std::string& indent) {
  std::string out;
  for (const auto& [key, value] : counters.items()) {
    if (key == "server" || key == "servers") continue;  // server_lines()
    std::string label = key;
    for (const auto& counter : dds::protocol::kServerCounters)
      if (key == counter.name) label = counter.meaning;
    out += indent + label + std::string(label.size() < 42 ? 42 - label.size() : 1, ' ') +
           (value.is_string() ? value.get<std::string>() : value.dump()) + "\n";
  }
  return out;
}

// With a shared store (leases): which server answered, then a column per server id, the number
// of vehicles it holds and their ids.
std::string server_lines(const ordered_json& status) {
  if (!status.contains("servers") || !status["servers"].is_array()) return {};
  std::string out = "\nanswered by " + status.value("server", std::string("?")) + "\n";
  std::size_t width = 6;
  for (const auto& server : status["servers"]) width = std::max(width, server.value("id", std::string()).size());
  const auto pad = [&](const std::string& text) { return text + std::string(width + 2 - text.size(), ' '); };
  out += pad("SERVER") + "VEHICLES\n";
  for (const auto& server : status["servers"]) {
    const auto vehicles = server.value("vehicles", ordered_json::array());
    std::string list;
    for (const auto& v : vehicles) list += " " + (v.is_string() ? v.get<std::string>() : v.dump());
    out += pad(server.value("id", std::string("?"))) + std::to_string(vehicles.size()) + list + "\n";
  }
  return out;
}

}  // namespace

std::string status_text(const ShardReplies& replies) {
  if (replies.count() == 1 && replies.complete()) {
    const auto status = parse_payload(replies.replies().begin()->second, "status");
    return counter_lines(status, "") + server_lines(status);
  }
  std::string out;
  for (const auto& [index, reply] : replies.replies())
    out += "shard " + name_of(reply) + "\n" + counter_lines(parse_payload(reply, "status"), "  ");
  for (const auto index : replies.missing())
    out += "shard " + shard_name(index, replies.count()) + ": did not answer\n";
  return out;
}

std::string missing_note(const ShardReplies& replies, std::int64_t timeout_ms, const std::string& what) {
  const auto missing = replies.missing();
  if (missing.empty()) return {};
  std::string names;
  for (const auto index : missing) names += (names.empty() ? "" : ", ") + shard_name(index, replies.count());
  return (missing.size() == 1 ? "shard " + names + " did not" : "shards " + names + " did not") +
         " answer within " + std::to_string(timeout_ms) + " ms: " +
         (missing.size() == 1 ? "its " : "their ") + what + " are not included";
}

}  // namespace dynid::cli
