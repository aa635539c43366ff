#pragma once
// ParsedRequest: an engineer's request (dds::Request) checked against the request kinds the
// server knows, before any work is queued.
//
//   kind        arguments (* required, + repeatable)           reply
//   vehicles    format                                          the vehicles of this shard
//   runs        vehicle*, format                                runs with ledger marks
//   estimate    vehicle*, run, model, format                    estimate tables (latest run)
//   pooled      vehicle*, run*+, model, format                  merged accumulators' estimate
//   close       vehicle*, run*, format                          final tables; run closed
//   reprocess   vehicle*, run*, model*, effects, format         replay into a fresh processor
//   base        vehicle*, run*, model*, format                  base-parameter report
//   residual    vehicle*, run*, model*, effects, candidates,    ranked candidate effects
//               format                                          (residual_requests.hpp)
//   add-effect  vehicle*, run*, model*, effect*, effects,       before/after report
//               format
//   status      format                                          the server's counters
//   fleet       model*, shared*+, vehicles*, format             fleet estimate (ls/fleet.hpp)
// vehicles is a comma-separated list; a fleet spans the vehicles of one shard.
// format is "text" (default) or "json" ("text" or "html" for residual and add-effect); effects
// and candidates are comma-separated lists.
//
// parse_request() throws InputError naming the request ("request alice@host/42#7") and the
// problem: an unknown kind, an unknown, missing, repeated or empty argument, a bad format, a
// vehicle (or an item of vehicles) or run that breaks the id rule (input/ids.hpp). What the
// message shows of the request (client, kind, argument names, ids) is escaped.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynid/dds/request.hpp"

namespace dynid::server {

struct ParsedRequest {
  std::string kind;
  std::map<std::string, std::vector<std::string>> arguments;

  std::optional<std::string> optional(const std::string& name) const;
  /// The value of a required argument (parse_request checked it is there).
  const std::string& required(const std::string& name) const;
  std::vector<std::string> all(const std::string& name) const;
  bool json() const { return optional("format") == std::optional<std::string>("json"); }
};

ParsedRequest parse_request(const dds::Request& request);

/// "a,b,,c" -> {"a", "b", "c"}.
std::vector<std::string> split_list(const std::string& text);

/// "name=value" arguments (the trace's references) as a map; InputError naming the argument when
/// one has no '=', an empty name, a value that is not a finite number, or a name given twice.
std::map<std::string, double> parse_references(const std::vector<std::string>& arguments);

/// The trace's `rounds`: absent = 4; InputError unless an integer in 0..10.
int parse_rounds(const std::optional<std::string>& text);

/// export's `part`: absent = 1; InputError unless an integer from 1 (to a million).
int parse_part(const std::optional<std::string>& text);

/// add-effect's and trace's `series`: absent = false, "yes" = true; InputError otherwise.
bool parse_series(const std::optional<std::string>& text);

}  // namespace dynid::server
