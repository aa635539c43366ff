// Server: construction, the dispatch loop's frame, and request execution (server.hpp).
#include "dynid/server/server.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <dynid/input/ids.hpp>

#include "dynid/dds/conversions.hpp"
#include "dynid/dds/topics.hpp"
#include "dynid/error.hpp"
#include "dynid/report/excitation_report.hpp"
#include "dynid/report/json.hpp"
#include "dynid/store/location.hpp"
#include "server_impl.hpp"

namespace dynid::server {

namespace {

std::vector<std::unique_ptr<RunService>> make_services(ServerContext& context, unsigned count) {
  std::vector<std::unique_ptr<RunService>> services;
  for (unsigned k = 0; k < count; ++k) services.push_back(std::make_unique<RunService>(context));
  return services;
}

// Workers wake at least this often to publish estimates whose interval has passed.
std::chrono::milliseconds tick_period(const ServerOptions& options) {
  return std::clamp(options.publish_interval / 2, std::chrono::milliseconds(5),
                    std::chrono::milliseconds(100));
}

// With a shared store, the server's id and the fence: its store refuses every write of a
// vehicle whose lease it does not hold (store.hpp, Leases).
ServerOptions with_holder(ServerOptions options) {
  if (!options.leased()) return options;
  if (options.server_id.empty()) options.server_id = default_server_id();
  options.store.holder = options.server_id;
  options.store.shared = true;  // the lease keeper's unfenced connection too
  return options;
}

}  // namespace

Server::Impl::Impl(ServerOptions opts)
    : options(with_holder(std::move(opts))),
      store(options.store_path, options.store),
      participant({options.domain, cyclone_config_uri(options.cyclone_config)}),
      announcements(participant, {dds::kAllVehiclesPartition}),
      chunks(participant, {dds::kAllVehiclesPartition}),
      requests(participant, {}),
      replies(participant, {}),
      services(make_services(context, options.worker_count())),
      pool(options.worker_count(), 256, tick_period(options),
           [this](std::size_t worker) {
             services[worker]->publish_due(std::chrono::steady_clock::now());
           }),
      waitset(dds::check(dds_create_waitset(participant.handle()), "dds_create_waitset")),
      stop_guard(dds::check(dds_create_guardcondition(participant.handle()),
                            "dds_create_guardcondition")) {
  if (!options.leased()) refuse_foreign_vehicles();  // shared: every server sees every vehicle
  for (const dds_entity_t reader : {announcements.handle(), chunks.handle(), requests.handle()}) {
    conditions.emplace_back(dds::check(dds_create_readcondition(reader, DDS_ANY_STATE),
                                       "dds_create_readcondition"));
    dds::check(dds_waitset_attach(waitset.get(), conditions.back().get(), 0), "dds_waitset_attach");
  }
  dds::check(dds_waitset_attach(waitset.get(), stop_guard.get(), 0), "dds_waitset_attach");
  for (std::size_t k = 0; k < services.size(); ++k)
    services[k]->set_waker([this, k] {
      pool.post_unbounded(k, [this, k] { services[k]->collect_committed(); });
    });
  if (options.leased()) {
    start_leases();  // a vehicle's runs are loaded when its lease is taken
    spdlog::info("dynid-server {}: store {} (shared, leases of {} ms), domain {}, {} workers, "
                 "checkpoint every {}",
                 options.server_id, store::for_messages(options.store_path), options.lease_ttl.count(),
                 options.domain, pool.size(), options.checkpoint_every);
    return;
  }
  resume_open_runs();
  spdlog::info("dynid-server: store {}, domain {}, {} workers, shard {}, checkpoint every {}",
               store::for_messages(options.store_path), options.domain, pool.size(), options.shard.to_string(),
               options.checkpoint_every);
}

void Server::Impl::start_leases() {
  for (auto& service : services)
    service->set_lease_lost([this](const std::string& vehicle) { leases->forget(vehicle); });
  leases = std::make_unique<LeaseKeeper>(
      options.store_path, options.store, options.server_id, options.lease_ttl,
      [this](const std::string& vehicle, bool shed) {
        const std::size_t worker = pool.worker_of(vehicle);
        pool.post_unbounded(worker, [this, worker, vehicle, shed] {
          services[worker]->forget(vehicle, shed);
          if (shed) leases->release(vehicle);  // after its last acknowledged write
        });
      });
}

Server::Impl::~Impl() {
  if (leases) leases->stop();  // no lease changes hands while the workers finish
  pool.stop();  // finish what is queued while the services and writers still exist
  for (auto& service : services) {  // and what is at the committer (acks, folds, marks)
    try {
      service->settle();
    } catch (const std::exception& e) {
      spdlog::error("stopping: {}", e.what());
    }
  }
  committer.stop();  // nothing calls back into the pool or the services after this
  // Every acknowledged write is durable: the others may take the vehicles over now, not a TTL
  // later.
  if (leases) leases->release_all();
  spdlog::info("dynid-server stopped; counters {}", counters.snapshot().to_json());
}

// A store holding vehicles of another shard was written by a server started with another
// --shard (or N changed): serving from it would split those vehicles' runs over two stores.
void Server::Impl::refuse_foreign_vehicles() {
  const auto foreign = options.shard.foreign_vehicles(store.with([](store::Store& s) { return s.list_vehicles(); }));
  if (foreign.empty()) return;
  std::string list;
  for (std::size_t k = 0; k < foreign.size() && k < 5; ++k)
    list += (k ? ", " : "") + foreign[k] + " (shard " +
            std::to_string(Shard::owner_of(foreign[k], options.shard.count)) + ")";
  if (foreign.size() > 5) list += ", ...";
  throw InputError("--shard " + options.shard.to_string() + ": store " +
                   store::for_messages(options.store_path) + " holds " +
                   std::to_string(foreign.size()) + " vehicle(s) of other shards: " + list +
                   "; was it written with another --shard? Vehicles do not move between shards "
                   "(docs/DESIGN.md, Scale-out)");
}

void Server::Impl::resume_open_runs() {
  const auto open = store.with([&](store::Store& s) {
    std::vector<store::RunKey> keys;
    for (const auto& vehicle : s.list_vehicles()) {
      if (!options.shard.owns(vehicle)) continue;
      for (const auto& run : s.list_runs(vehicle))
        if (!run.closed) keys.push_back({vehicle, run.run});
    }
    return keys;
  });
  for (const auto& key : open) {
    const std::size_t worker = pool.worker_of(key.vehicle);
    pool.post(worker, [this, key, worker] { services[worker]->resume(key); });
  }
  if (!open.empty()) spdlog::info("resuming {} open runs", open.size());
}

Server::Server(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
Server::~Server() = default;

void Server::run() {
  while (!impl_->stopping.load()) {
    dds_waitset_wait(impl_->waitset.get(), nullptr, 0, DDS_MSECS(500));
    if (impl_->stopping.load()) break;
    try {
      impl_->dispatch_round();
    } catch (const std::exception& e) {  // a DDS failure while taking: log, go on
      spdlog::error("dispatcher: {}", e.what());
    }
  }
}

void Server::stop() {
  impl_->stopping.store(true);
  impl_->in_flight.stop();  // the requests being computed end at their next cancellation point
  impl_->stopping_work->cancel("the server is stopping");
  dds_set_guardcondition(impl_->stop_guard.get(), true);
}

CounterSnapshot Server::counters() const { return impl_->counters.snapshot(); }

// ---- requests ----------------------------------------------------------------------------

// The counters, and with leases which server this is and who holds which vehicle:
// {..counters.., "server": id, "servers": [{"id": id, "vehicles": [..]}, ..]}.
std::string Server::Impl::status_reply() {
  std::string out = counters.snapshot().to_json();
  if (!leases) return out;
  out.pop_back();  // the counters' closing brace
  out += ",\"server\":" + report::json_string(options.server_id) + ",\"servers\":[";
  bool first_server = true;
  for (const auto& [server, vehicles] : holdings(leases->leases())) {
    out += std::string(first_server ? "" : ",") + "{\"id\":" + report::json_string(server) + ",\"vehicles\":[";
    for (std::size_t k = 0; k < vehicles.size(); ++k) out += (k ? "," : "") + report::json_string(vehicles[k]);
    out += "]}";
    first_server = false;
  }
  return out + "]}";
}

std::string Server::Impl::fleet_reply(const ParsedRequest& request) {
  if (request.kind == "status") return status_reply();
  auto vehicles = store.with([](store::Store& s) { return s.list_vehicles(); });
  std::string out;
  for (const auto& v : vehicles)
    out += request.json() ? (out.empty() ? "" : ",") + report::json_string(v) : v + "\n";
  return request.json() ? "[" + out + "]" : out;
}

dds::Reply Server::Impl::execute(const ParsedRequest& r, RunService& service) {
  const auto format = r.json() ? "application/json" : "text/plain";
  if (r.kind == "vehicles" || r.kind == "status")
    return {{}, 0, dds::ReplyStatus::kOk, {}, r.kind == "status" ? "application/json" : format,
            fleet_reply(r)};
  const std::string& vehicle = r.required("vehicle");
  std::string payload;
  if (r.kind == "runs") {
    payload = service.list_runs(vehicle, r.json());
  } else if (r.kind == "estimate") {
    payload = render(service.estimate(vehicle, r.optional("run"), r.optional("model")), r.json());
  } else if (r.kind == "excitation") {
    const report::ExcitationReport report = service.excitation(vehicle, r.optional("run"));
    payload = r.json() ? report::excitation_json(report) : report::format_excitation_text(report);
  } else if (r.kind == "pooled") {
    payload = render(service.pooled(vehicle, r.all("run"), r.optional("model")), r.json());
  } else if (r.kind == "close") {
    payload = render(service.close(vehicle, r.required("run")), r.json());
  } else if (r.kind == "reprocess") {
    payload = render(service.reprocess(vehicle, r.required("run"), r.required("model"),
                                       split_list(r.optional("effects").value_or(""))),
                     r.json());
  } else if (r.kind == "base") {
    payload = service.base_report(vehicle, r.required("run"), r.required("model"), r.json());
  } else if (r.kind == "residual" || r.kind == "add-effect" || r.kind == "trace" ||
             r.kind == "consistency" || r.kind == "iv" || r.kind == "simex" || r.kind == "export") {
    ResidualRequest request{r.optional("model").value_or(""),
                            std::nullopt,
                            split_list(r.optional("candidates").value_or("")),
                            r.kind == "add-effect" ? r.required("effect") : "",
                            r.optional("format").value_or("text"),
                            r.kind,
                            parse_references(r.all("reference")),
                            parse_rounds(r.optional("rounds"))};
    request.series = parse_series(r.optional("series"));
    request.part = parse_part(r.optional("part"));
    if (const auto effects = r.optional("effects"))  // "none": the model with no effect declared
      request.effects = *effects == "none" ? std::vector<std::string>{} : split_list(*effects);
    ResidualReply reply = service.residual(vehicle, r.required("run"), request);
    return {{}, 0, dds::ReplyStatus::kOk, {}, reply.payload_format, std::move(reply.payload)};
  }
  return {{}, 0, dds::ReplyStatus::kOk, {}, format, payload};
}

void Server::Impl::send(dds::Reply reply) {
  reply.shard = options.shard.index;  // the client counts the shards that answered
  reply.shard_count = options.shard.count;
  std::lock_guard lock(reply_mutex);
  try {
    replies.write(to_wire(reply).data);
  } catch (const std::exception& e) {
    spdlog::error("reply to {}#{} not sent: {}", input::printable(reply.client), reply.correlation_id, e.what());
  }
}

bool ReplyCache::begin(const Key& key, std::optional<dds::Reply>& cached) {
  std::lock_guard lock(mutex_);
  if (const auto it = replies_.find(key); it != replies_.end()) {
    cached = it->second;
    return false;
  }
  replies_.emplace(key, std::nullopt);
  order_.push_back(key);
  if (order_.size() > kCapacity) {
    replies_.erase(order_.front());
    order_.pop_front();
  }
  return true;
}

void ReplyCache::finish(const Key& key, const dds::Reply& reply) {
  std::lock_guard lock(mutex_);
  if (const auto it = replies_.find(key); it != replies_.end()) it->second = reply;
}

}  // namespace dynid::server
