// RunService: the run-level requests (estimate, pooled, close, reprocess, base, runs).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <set>

#include "dynid/report/json.hpp"
#include "dynid/server/run_service.hpp"

namespace dynid::server {

namespace {

using report::json_number;
using report::json_string;

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

std::vector<std::string> names_of(const std::vector<model::ParameterInfo>& parameters) {
  std::vector<std::string> names;
  for (const auto& p : parameters) names.push_back(p.name);
  return names;
}

std::vector<std::string> group_names(const ls::EquationGroups& groups) {
  std::vector<std::string> names;
  for (std::size_t g = 0; g < groups.size(); ++g) names.push_back(groups.name(g));
  return names;
}

// The index of `model` among a processor's models, or npos.
std::size_t model_index(const std::vector<ingest::ModelEstimate>& estimates,
                        const std::string& model) {
  for (std::size_t m = 0; m < estimates.size(); ++m)
    if (estimates[m].model == model) return m;
  return std::string::npos;
}

// One model's groups of several runs merged group by group (the accumulator of all their rows).
// InputError when a run does not run the model or configures it differently.
struct MergedModel {
  std::vector<model::ParameterInfo> parameters;
  ls::EquationGroups groups;
};

MergedModel merge_runs(const std::vector<const ingest::RunProcessor*>& processors,
                       const std::vector<std::string>& runs, const std::string& model,
                       const std::string& what) {
  std::optional<MergedModel> pool;
  for (std::size_t r = 0; r < processors.size(); ++r) {
    const auto estimates = processors[r]->estimates();
    const std::size_t index = model_index(estimates, model);
    const ls::EquationGroups* groups =
        index == std::string::npos ? nullptr : processors[r]->groups(index);
    if (!groups) throw InputError(what + ": model " + model + " is not run in " + runs[r]);
    if (!pool) {
      pool.emplace(MergedModel{estimates[index].parameters,
                               ls::EquationGroups(groups->group(0).parameter_count(), group_names(*groups))});
    } else if (names_of(estimates[index].parameters) != names_of(pool->parameters) ||
               group_names(*groups) != group_names(pool->groups)) {
      throw InputError(what + ": runs " + runs.front() + " and " + runs[r] + " configure model " +
                       model + " differently (parameters, effects or groups)");
    }
    for (std::size_t g = 0; g < groups->size(); ++g) pool->groups.group(g).merge(groups->group(g));
  }
  return std::move(*pool);
}

}  // namespace

std::string RunService::latest_run(const std::string& vehicle) {
  const auto runs = context_.store.with([&](store::Store& s) {
    const auto vehicles = s.list_vehicles();
    if (std::find(vehicles.begin(), vehicles.end(), vehicle) == vehicles.end())
      throw NotFound("vehicle " + vehicle + ": unknown vehicle");
    return s.list_runs(vehicle);
  });
  if (runs.empty()) throw NotFound("vehicle " + vehicle + ": no run yet");
  return runs.back().run;
}

EstimateTables RunService::estimate(const std::string& vehicle,
                                    const std::optional<std::string>& run,
                                    const std::optional<std::string>& model) {
  settle();  // the chunks received before this request count, the ledger up to date
  const store::RunKey key{vehicle, run ? *run : latest_run(vehicle)};
  RunState& state = load(key);
  refresh_residual(key, state);  // a new verdict comes with a later publication
  // Published first when it changed since its last publication: the reply's tables are then the
  // topic's, revision for revision.
  if (dirty_.contains(key)) publish(key, state);
  const auto estimates = state.processor.estimates();
  auto tables = tables_of(vehicle, key.run, estimates, model);
  attach_live(state, estimates, tables);
  stamp_revisions(state, tables);
  if (model && tables.tables.empty() && tables.notes.empty())
    throw NotFound("run " + vehicle + "/" + key.run + " has no model " + *model);
  apply_health(tables, run_health(key, state), state.processor.announcement());
  if (!state.halted.empty()) tables.notes.push_back(key.run + ": " + state.halted);
  return tables;
}

report::ExcitationReport RunService::excitation(const std::string& vehicle, const std::optional<std::string>& run) {
  settle();  // the chunks received before this request count, the ledger up to date
  const store::RunKey key{vehicle, run ? *run : latest_run(vehicle)};
  RunState& state = load(key);
  report::ExcitationReport out =
      excitation_of(vehicle, key.run, state.processor.estimates(), run_health(key, state),
                    state.processor.announcement());
  if (!state.halted.empty()) out.notes.push_back(key.run + ": " + state.halted);
  return out;
}

EstimateTables RunService::pooled(const std::string& vehicle, const std::vector<std::string>& runs,
                                  const std::optional<std::string>& model) {
  settle();  // the chunks received before this request count, the ledger up to date
  if (runs.empty()) throw InputError("pooled: name at least one run");
  if (std::set<std::string>(runs.begin(), runs.end()).size() != runs.size())
    throw InputError("pooled: a run is named twice (" + join(runs, ", ") + ")");
  std::vector<const ingest::RunProcessor*> processors;
  for (const auto& run : runs) processors.push_back(&load({vehicle, run}).processor);
  const auto first = processors.front()->estimates();
  EstimateTables out;
  const std::string source = "pool:" + join(runs, "+");
  for (std::size_t m = 0; m < first.size(); ++m) {
    if (model && first[m].model != *model) continue;
    const ls::EquationGroups* base = processors.front()->groups(m);
    if (!base) {
      out.notes.push_back(first[m].model + ": not run in " + runs.front());
      continue;
    }
    const MergedModel pool = merge_runs(processors, runs, first[m].model, "pooled");
    try {
      out.tables.push_back(table_of(vehicle, source, first[m].model, first[m].parameters, pool.groups.estimate()));
    } catch (const InputError& e) {
      out.notes.push_back(first[m].model + ": " + e.what());
    }
  }
  if (model && out.tables.empty() && out.notes.empty())
    throw NotFound("pooled: run " + runs.front() + " has no model " + *model);
  publish_pending(vehicle);  // the pool comes last: no throttled run table overtakes it
  publish_tables(vehicle, out);
  return out;
}

FleetSource RunService::fleet_member(const std::string& vehicle, const std::string& model) {
  settle();  // the chunks received before this request count, the ledger up to date
  latest_run(vehicle);  // NotFound for an unknown vehicle or one without runs
  const auto stored = context_.store.with([&](store::Store& s) { return s.list_runs(vehicle); });
  FleetSource out;
  std::vector<const ingest::RunProcessor*> processors;
  for (const auto& r : stored) {
    if (!r.closed) continue;
    const ingest::RunProcessor& p = load({vehicle, r.run}).processor;
    const std::size_t index = model_index(p.estimates(), model);
    if (index == std::string::npos || p.groups(index) == nullptr) continue;
    out.runs.push_back(r.run);
    processors.push_back(&p);
  }
  if (out.runs.empty()) {  // nothing closed yet: the latest run, open or not
    out.runs = {stored.back().run};
    processors = {&load({vehicle, stored.back().run}).processor};
  }
  MergedModel merged = merge_runs(processors, out.runs, model, "fleet: vehicle " + vehicle);
  std::vector<ls::FleetParameter> parameters;
  for (const auto& p : merged.parameters) parameters.push_back({p.name, p.unit});
  out.member.emplace(ls::FleetMember{vehicle, std::move(parameters), std::move(merged.groups)});
  return out;
}

EstimateTables RunService::close(const std::string& vehicle, const std::string& run) {
  settle();  // the chunks received before this request count, the ledger up to date
  const store::RunKey key{vehicle, run};
  RunState& state = load(key);
  if (!state.processor.finished()) state.processor.finish();  // folds the held-back samples
  context_.store.with([&](store::Store& s) { s.close_run(key); });
  publish(key, state);  // and the finished run's live verdict, once diagnosed
  const auto estimates = state.processor.estimates();
  auto tables = tables_of(vehicle, run, estimates);
  attach_live(state, estimates, tables);
  apply_health(tables, run_health(key, state), state.processor.announcement());
  stamp_revisions(state, tables);
  record_history(key, tables);
  spdlog::info("run {}/{}: closed", vehicle, run);
  return tables;
}

EstimateTables RunService::reprocess(const std::string& vehicle, const std::string& run,
                                     const std::string& model,
                                     const std::vector<std::string>& effects) {
  settle();  // the chunks received before this request count, the ledger up to date
  const store::RunKey key{vehicle, run};
  const RunState& state = load(key);
  ingest::RunAnnouncement announcement = state.processor.announcement();
  ingest::ModelSpec spec{model, {}, effects};
  for (const auto& announced : announcement.models)
    if (announced.model == model) spec.constants = announced.constants;  // the profile's
  announcement.models = {spec};
  ingest::RunProcessor processor(announcement, context_.options.store.limits);
  replay_stored(key, state, [&](const ingest::Chunk& chunk) { processor.push(chunk); });
  if (state.processor.finished()) processor.finish();
  return tables_of(vehicle, "reprocess:" + run, processor.estimates());
}

void RunService::replay_stored(const store::RunKey& key, const RunState& state,
                               const std::function<void(const ingest::Chunk&)>& sink) {
  // A few chunks at a time: a long run is never held whole in the store's read buffers.
  for (std::uint64_t next = 0; state.contiguous >= 0 &&
                               next <= static_cast<std::uint64_t>(state.contiguous);) {
    cancellation_point();  // a long run read for a request nobody waits for any more
    const auto to = std::min<std::uint64_t>(next + 15, static_cast<std::uint64_t>(state.contiguous));
    for (const auto& chunk : read_chunks(key, next, to)) sink(chunk);
    next = to + 1;
  }
}

const ingest::RunHealth& RunService::run_health(const store::RunKey& key, RunState& state) {
  if (state.contiguous < 0 || state.health_through == state.contiguous) return state.health;
  std::vector<ingest::Chunk> chunks;
  replay_stored(key, state, [&](const ingest::Chunk& chunk) { chunks.push_back(chunk); });
  state.health =
      ingest::channel_health(ingest::assemble_run(state.processor.announcement(), chunks));
  state.health_through = state.contiguous;
  return state.health;
}

ResidualReply RunService::residual(const std::string& vehicle, const std::string& run,
                                   const ResidualRequest& request) {
  settle();  // the chunks received before this request count, the ledger up to date
  const store::RunKey key{vehicle, run};
  const RunState& state = load(key);
  std::vector<ingest::Chunk> chunks;
  replay_stored(key, state, [&](const ingest::Chunk& chunk) { chunks.push_back(chunk); });
  return residual_reply(state.processor.announcement(), chunks, request);
}

std::string RunService::base_report(const std::string& vehicle, const std::string& run,
                                    const std::string& model, bool json) {
  settle();  // the chunks received before this request count, the ledger up to date
  const RunState& state = load({vehicle, run});
  const auto estimates = state.processor.estimates();
  const std::size_t m = model_index(estimates, model);
  if (m == std::string::npos) throw NotFound("run " + vehicle + "/" + run + " has no model " + model);
  if (!estimates[m].estimate)
    throw NotFound("model " + model + " of " + vehicle + "/" + run + ": no estimate (" + estimates[m].note + ")");
  const auto& s = estimates[m].estimate->estimate.structure;
  const auto names = names_of(estimates[m].parameters);
  std::vector<std::string> entries;
  std::string text = fmt::format("{}/{} {}: {} base parameters of {} (tau {:.3g})\n", vehicle, run,
                                 model, s.rank(), names.size(), s.tolerance);
  for (std::size_t j = 0; j < names.size(); ++j) {
    const auto index = static_cast<Eigen::Index>(j);
    std::string relation;
    if (s.status[j] == ls::ParameterStatus::kRegrouped) {
      const auto k = std::find(s.base.begin(), s.base.end(), index) - s.base.begin();
      relation = s.relation(k, names);
    }
    const char* status = ls::to_string(s.status[j]);
    text += fmt::format("  {:<24} {:<11} {}\n", names[j], status, relation.empty() ? "" : "= " + relation);
    entries.push_back(fmt::format("{{\"name\":{},\"status\":{},\"relation\":{}}}", json_string(names[j]),
                                  json_string(status), json_string(relation)));
  }
  if (!json) return text;
  return fmt::format("{{\"vehicle\":{},\"run\":{},\"model\":{},\"rank\":{},\"tolerance\":{},\"parameters\":[{}]}}",
                     json_string(vehicle), json_string(run), json_string(model), s.rank(),
                     json_number(s.tolerance), join(entries, ","));
}

std::string RunService::list_runs(const std::string& vehicle, bool json) {
  settle();  // the chunks received before this request count, the ledger up to date
  latest_run(vehicle);  // NotFound for an unknown vehicle or one without runs
  const auto runs = context_.store.with([&](store::Store& s) { return s.list_runs(vehicle); });
  // Text for people: counts of chunks, not the ledger's sequence marks (chunks #0..#39 stored is
  // "40 in order"); JSON keeps the marks and adds the counts.
  const auto count = [](const std::optional<std::uint64_t>& mark) { return mark ? *mark + 1 : 0; };
  std::string text = fmt::format("{:<32} {:<7} {:>8} {:>9} {:>8}  {}\n", "run", "state", "stored",
                                 "in order", "folded", "complete");
  std::vector<std::string> entries;
  for (const auto& r : runs) {
    const RunState* loaded = find({vehicle, r.run});
    const std::string halted = loaded ? loaded->halted : std::string();
    const std::uint64_t in_order = count(r.contiguous_through), folded = count(r.folded_through);
    std::string complete;
    if (!halted.empty()) complete = "no: halted, " + halted;
    else if (r.chunks_stored > in_order)
      complete = fmt::format("no: {} stored after a missing chunk #{}", r.chunks_stored - in_order, in_order);
    else if (folded < in_order) complete = fmt::format("no: {} to fold", in_order - folded);
    else complete = r.closed ? "yes" : "so far (run open)";
    text += fmt::format("{:<32} {:<7} {:>8} {:>9} {:>8}  {}\n", r.run, r.closed ? "closed" : "open",
                        r.chunks_stored, in_order, folded, complete);
    entries.push_back(fmt::format(
        "{{\"run\":{},\"closed\":{},\"contiguous_through\":{},\"folded_through\":{},"
        "\"chunks_stored\":{},\"chunks_in_order\":{},\"chunks_folded\":{},\"halted\":{}}}",
        json_string(r.run), r.closed, r.contiguous_through ? std::to_string(*r.contiguous_through) : "null",
        r.folded_through ? std::to_string(*r.folded_through) : "null", r.chunks_stored, in_order, folded,
        json_string(halted)));
  }
  text += "chunks: stored = held by the store; in order = stored without a gap from chunk #0; "
          "folded = in the estimates\n";
  return json ? "[" + join(entries, ",") + "]" : text;
}

}  // namespace dynid::server
