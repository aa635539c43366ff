#pragma once
// The reply to a `fleet` request: the fleet estimate (ls/fleet.hpp) of one model over several
// vehicles, as a text table or JSON.
//
// Text: a header (model, vehicles with the runs used, rows, rank, sigma), a RANK DEFICIENT line
// when the stacked system is, the parameters (shared first, then "<vehicle>/<name>") with
// value, std, relative std and status, then one line per vehicle with its rows and unweighted
// residual RMS. JSON carries the same with every number round-trip exact (report/json.hpp).
#include <string>
#include <vector>

#include "dynid/ls/fleet.hpp"

namespace dynid::server {

struct FleetReply {
  std::string model;
  std::vector<std::string> shared;
  std::vector<std::vector<std::string>> runs;  ///< per vehicle, in the estimate's order
  ls::FleetEstimate estimate;
};

std::string render_fleet(const FleetReply& reply, bool json);

}  // namespace dynid::server
