// Server::Impl::dispatch_fleet: a request over several vehicles. Every RunService belongs to
// one worker thread, so each vehicle's accumulators are read by a task on its own worker; the
// tasks meet in a FleetGather and the last one to finish solves and replies. No worker waits
// for another (a worker blocking on a future could wait on itself or on a full queue).
#include <exception>
#include <map>
#include <mutex>
#include <set>

#include "dynid/server/fleet_report.hpp"
#include "server_impl.hpp"

namespace dynid::server {

namespace {

struct FleetGather {
  ParsedRequest parsed;
  dds::Request request;
  ReplyCache::Key key;
  std::vector<std::string> vehicles;
  std::mutex mutex;
  std::vector<FleetSource> sources;  // per vehicle
  std::size_t remaining = 0;
  std::exception_ptr error;  // the first vehicle that failed
};

// The refusal of a fleet whose vehicles have different owners. Every owner involved sends the
// same text, so the engineer reads the same answer whichever arrives first.
std::string spanning_shards(const std::vector<std::string>& vehicles, std::uint32_t count) {
  std::map<std::uint32_t, std::string> by_shard;
  for (const auto& v : vehicles) {
    auto& list = by_shard[Shard::owner_of(v, count)];
    list += (list.empty() ? "" : ",") + v;
  }
  std::string where;
  for (const auto& [index, list] : by_shard)
    where += (where.empty() ? "" : "; ") + list + " on shard " + std::to_string(index) + "/" + std::to_string(count);
  return "fleet: the vehicles are served by different servers (" + where +
         "): a fleet estimate solves the shared parameters of all its vehicles in one "
         "factorization on one server, so it spans one shard's vehicles; ask per shard "
         "(docs/DESIGN.md, Scale-out)";
}

std::vector<std::string> fleet_vehicles(const ParsedRequest& request, const Shard& shard) {
  const auto vehicles = split_list(request.required("vehicles"));
  if (vehicles.empty()) throw InputError("fleet: name at least one vehicle (--vehicles V1,V2,...)");
  if (std::set<std::string>(vehicles.begin(), vehicles.end()).size() != vehicles.size())
    throw InputError("fleet: a vehicle is named twice (" + request.required("vehicles") + ")");
  if (!shard.foreign_vehicles(vehicles).empty()) throw InputError(spanning_shards(vehicles, shard.count));
  return vehicles;
}

dds::Reply solve(FleetGather& g) {
  if (g.error) std::rethrow_exception(g.error);
  FleetReply reply{g.parsed.required("model"), g.parsed.all("shared"), {}, {}};
  std::vector<ls::FleetMember> members;
  for (auto& source : g.sources) {
    members.push_back(std::move(*source.member));
    reply.runs.push_back(source.runs);
  }
  reply.estimate = ls::fleet_estimate(members, reply.shared);
  return {{}, 0, dds::ReplyStatus::kOk, {}, g.parsed.json() ? "application/json" : "text/plain",
          render_fleet(reply, g.parsed.json())};
}

}  // namespace

void Server::Impl::dispatch_fleet(const ParsedRequest& parsed, const dds::Request& raw,
                                  const ReplyCache::Key& key) {
  std::vector<std::string> vehicles;
  try {
    vehicles = fleet_vehicles(parsed, options.shard);
  } catch (const InputError&) {
    const auto error = std::current_exception();
    return answer(raw, key, [&]() -> dds::Reply { std::rethrow_exception(error); });
  }
  auto gather = std::make_shared<FleetGather>();
  gather->parsed = parsed;
  gather->request = raw;
  gather->key = key;
  gather->vehicles = vehicles;
  gather->sources.resize(vehicles.size());
  gather->remaining = vehicles.size();
  for (std::size_t v = 0; v < vehicles.size(); ++v) {
    const std::size_t worker = pool.worker_of(vehicles[v]);
    pool.post(worker, [this, gather, v, worker] {
      try {
        FleetSource source = services[worker]->fleet_member(gather->vehicles[v], gather->parsed.required("model"));
        std::lock_guard lock(gather->mutex);
        gather->sources[v] = std::move(source);
      } catch (...) {
        std::lock_guard lock(gather->mutex);
        if (!gather->error) gather->error = std::current_exception();
      }
      bool last = false;
      {
        std::lock_guard lock(gather->mutex);
        last = --gather->remaining == 0;
      }
      if (last) answer(gather->request, gather->key, [&] { return solve(*gather); });
    });
  }
}

}  // namespace dynid::server
