#pragma once
// FleetState: what the dashboard shows, kept in memory from what it receives: every published
// estimate (the Estimate topic, all vehicles) as a point of its model's history, and the fleet
// (vehicles and their runs) as the server last listed it.
//
// Contract:
// - add() keeps one point per publication of (vehicle, run, model): revision, rows, the
//   residual RMS, the live verdict, and per parameter its value, standard deviation and status.
//   A history holds at most `history_limit` points: when full, every second point is dropped,
//   so a long run keeps its whole span at a coarser step. A revision at or below the last one
//   kept (a late or repeated sample) is not added.
// - Every added point gets the next sequence number; wait_events() blocks until there is a
//   point after `after` (or `timeout`) and returns those still in the event ring (the newest
//   kEventRing), oldest first: what a server-sent-event stream sends. close() ends the waits.
// - The JSON texts are complete documents, built under the lock, safe to send as they are.
// - Thread-safe: the DDS reader, the fleet poller and the HTTP handlers share one instance.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "dynid/dds/estimate_table.hpp"

namespace dynid::dashboard {

/// One publication of a model's estimate: what its plots need.
struct EstimatePoint {
  std::uint64_t revision = 0;
  std::uint64_t rows = 0;
  double residual_rms = 0.0;
  std::vector<double> value;  ///< per parameter, NaN when not identifiable
  std::vector<double> std;
  std::vector<std::string> status;
};

/// A published estimate, as a server-sent event announces it.
struct EstimateEvent {
  std::uint64_t sequence = 0;
  std::string vehicle, run, model;
  std::uint64_t revision = 0;
};

class FleetState {
 public:
  static constexpr std::size_t kEventRing = 1024;
  explicit FleetState(std::size_t history_limit = 1000);

  void add(const dds::EstimateTable& table);
  /// The fleet as polled: `vehicles_json` an array of {"vehicle", "runs"} objects, or `error`
  /// when no server answered.
  void set_fleet(std::string vehicles_json, std::string error);

  /// {"vehicles": [...], "fleet_error": "...", "models": [{vehicle, run, model, revision, rows,
  /// estimator, verdict, statuses: {status: count}}], "sequence": n}
  std::string fleet_json() const;
  /// {"vehicle", "run", "model", "parameters": [{name, unit}], "points": [...], "latest": the
  /// newest table as dynid estimates --json gives it}; NotFound-like empty string when unknown.
  std::string history_json(const std::string& vehicle, const std::string& run,
                           const std::string& model) const;

  std::vector<EstimateEvent> wait_events(std::uint64_t after,
                                         std::chrono::milliseconds timeout) const;
  std::uint64_t sequence() const;
  /// Ends every wait at once, and the streams with it: the dashboard is stopping.
  void close();
  bool closed() const;

 private:
  using Key = std::tuple<std::string, std::string, std::string>;  // vehicle, run, model
  struct History {
    std::vector<std::string> names, units;
    std::deque<EstimatePoint> points;
    std::string latest_json;
    std::string estimator, verdict;
  };
  std::size_t history_limit_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::map<Key, History> histories_;
  std::deque<EstimateEvent> events_;
  std::uint64_t sequence_ = 0;
  bool closed_ = false;
  std::string vehicles_json_ = "[]";
  std::string fleet_error_;
};

}  // namespace dynid::dashboard
