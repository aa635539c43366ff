#include "dynid/dashboard/fleet_state.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

#include "dynid/report/estimate_report.hpp"

namespace dynid::dashboard {
namespace {

using nlohmann::json;

// JSON has no NaN: a value that is not identifiable is null, as estimate_json writes it.
json number(double x) {
  return std::isfinite(x) ? json(x) : json(nullptr);
}

json point_json(const EstimatePoint& p) {
  json values = json::array(), stds = json::array();
  for (std::size_t k = 0; k < p.value.size(); ++k) {
    values.push_back(number(p.value[k]));
    stds.push_back(number(p.std[k]));
  }
  return {{"revision", p.revision}, {"rows", p.rows}, {"residual_rms", number(p.residual_rms)},
          {"value", values},        {"std", stds},    {"status", p.status}};
}

// Every second point dropped, the newest kept: the history's span stays the run's.
void thin(std::deque<EstimatePoint>& points) {
  std::deque<EstimatePoint> kept;
  const std::size_t n = points.size();
  for (std::size_t k = n % 2 == 0 ? 1 : 0; k < n; k += 2) kept.push_back(std::move(points[k]));
  points.swap(kept);
}

}  // namespace

FleetState::FleetState(std::size_t history_limit)
    : history_limit_(std::max<std::size_t>(history_limit, 4)) {}

void FleetState::add(const dds::EstimateTable& table) {
  EstimatePoint point;
  point.revision = table.revision;
  point.rows = table.rows;
  point.residual_rms = table.residual_rms;
  for (const dds::ParameterEntry& p : table.parameters) {
    point.value.push_back(p.value);
    point.std.push_back(p.standard_deviation);
    point.status.emplace_back(report::status_name(p.status));
  }
  std::string latest = report::estimate_json(table);
  {
    const std::lock_guard lock(mutex_);
    History& h = histories_[{table.vehicle, table.source, table.model}];
    if (!h.points.empty() && table.revision <= h.points.back().revision) return;
    h.names.clear(), h.units.clear();
    for (const dds::ParameterEntry& p : table.parameters)
      h.names.push_back(p.name), h.units.push_back(p.unit);
    // A model whose parameters changed (another profile on a new run of the same name) starts
    // its plots again: points of different parameters cannot share an axis.
    if (!h.points.empty() && h.points.back().value.size() != point.value.size()) h.points.clear();
    h.points.push_back(std::move(point));
    if (h.points.size() > history_limit_) thin(h.points);
    h.latest_json = std::move(latest);
    h.estimator = table.estimator;
    h.verdict = table.residual_verdict;
    events_.push_back({++sequence_, table.vehicle, table.source, table.model, table.revision});
    if (events_.size() > kEventRing) events_.pop_front();
  }
  changed_.notify_all();
}

void FleetState::set_fleet(std::string vehicles_json, std::string error) {
  const std::lock_guard lock(mutex_);
  vehicles_json_ = std::move(vehicles_json);
  fleet_error_ = std::move(error);
}

std::string FleetState::fleet_json() const {
  const std::lock_guard lock(mutex_);
  json models = json::array();
  for (const auto& [key, h] : histories_) {
    if (h.points.empty()) continue;
    const EstimatePoint& last = h.points.back();
    std::map<std::string, int> statuses;
    for (const std::string& s : last.status) ++statuses[s];
    models.push_back({{"vehicle", std::get<0>(key)},
                      {"run", std::get<1>(key)},
                      {"model", std::get<2>(key)},
                      {"revision", last.revision},
                      {"rows", last.rows},
                      {"estimator", h.estimator},
                      {"verdict", h.verdict},
                      {"statuses", statuses}});
  }
  json out = {{"vehicles", json::parse(vehicles_json_, nullptr, false)},
              {"fleet_error", fleet_error_},
              {"models", models},
              {"sequence", sequence_}};
  if (out["vehicles"].is_discarded()) out["vehicles"] = json::array();
  return out.dump();
}

std::string FleetState::history_json(const std::string& vehicle, const std::string& run,
                                     const std::string& model) const {
  const std::lock_guard lock(mutex_);
  const auto it = histories_.find({vehicle, run, model});
  if (it == histories_.end()) return {};
  const History& h = it->second;
  json parameters = json::array(), points = json::array();
  for (std::size_t k = 0; k < h.names.size(); ++k)
    parameters.push_back({{"name", h.names[k]}, {"unit", h.units[k]}});
  for (const EstimatePoint& p : h.points) points.push_back(point_json(p));
  json latest = json::parse(h.latest_json, nullptr, false);
  return json({{"vehicle", vehicle},
               {"run", run},
               {"model", model},
               {"parameters", parameters},
               {"points", points},
               {"latest", latest.is_discarded() ? json(nullptr) : latest},
               {"sequence", sequence_}})
      .dump();
}

std::vector<EstimateEvent> FleetState::wait_events(std::uint64_t after,
                                                   std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return closed_ || sequence_ > after; });
  std::vector<EstimateEvent> out;
  for (const EstimateEvent& e : events_)
    if (e.sequence > after) out.push_back(e);
  return out;
}

void FleetState::close() {
  {
    const std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

bool FleetState::closed() const {
  const std::lock_guard lock(mutex_);
  return closed_;
}

std::uint64_t FleetState::sequence() const {
  const std::lock_guard lock(mutex_);
  return sequence_;
}

}  // namespace dynid::dashboard
