#include "dynid/server/request_parser.hpp"

#include <set>

#include <dynid/input/ids.hpp>
#include <dynid/input/number.hpp>

#include "dynid/dds/protocol.hpp"
#include "dynid/error.hpp"

namespace dynid::server {

namespace {

// Vehicle ids and run names reach the store's queries, partitions and log lines: the id rule
// (input/ids.hpp) is checked here, before any work.
void check_ids(const ParsedRequest& parsed, const std::string& where) {
  const auto check = [&where](const std::string& argument, const std::string& value, bool vehicle) {
    try {
      vehicle ? input::check_vehicle_id(value) : input::check_run_name(value);
    } catch (const InputError& e) {
      throw InputError(where + ": argument '" + argument + "': " + e.what());
    }
  };
  for (const auto& [name, values] : parsed.arguments)
    for (const auto& value : values) {
      if (name == "vehicle" || name == "run") check(name, value, name == "vehicle");
      if (name == "vehicles")
        for (const auto& item : split_list(value)) check(name, item, true);
    }
}

}  // namespace

std::optional<std::string> ParsedRequest::optional(const std::string& name) const {
  const auto it = arguments.find(name);
  if (it == arguments.end() || it->second.empty()) return std::nullopt;
  return it->second.front();
}

const std::string& ParsedRequest::required(const std::string& name) const {
  return arguments.at(name).front();
}

std::vector<std::string> ParsedRequest::all(const std::string& name) const {
  const auto it = arguments.find(name);
  return it == arguments.end() ? std::vector<std::string>{} : it->second;
}

ParsedRequest parse_request(const dds::Request& request) {
  const std::string where =
      "request " + input::printable(request.client) + "#" + std::to_string(request.correlation_id);
  const dds::protocol::RequestKind* spec = dds::protocol::find_request_kind(request.kind);
  if (spec == nullptr)
    throw InputError(where + ": unknown kind '" + input::printable(request.kind) +
                     "' (known: " + dds::protocol::request_kind_names() + ")");
  ParsedRequest parsed{request.kind, {}};
  for (const auto& argument : request.arguments) {
    if (!spec->takes(argument.name))
      throw InputError(where + ": '" + request.kind + "' takes no argument '" +
                       input::printable(argument.name) + "'");
    if (argument.value.empty())
      throw InputError(where + ": argument '" + argument.name + "' is empty");
    auto& values = parsed.arguments[argument.name];
    if (!values.empty() && !spec->is_repeatable(argument.name))
      throw InputError(where + ": argument '" + argument.name + "' given twice");
    values.push_back(argument.value);
  }
  // In name order, so that the first missing one named does not depend on the table's order.
  std::set<std::string> required(spec->required.begin(), spec->required.end());
  for (const auto& name : required)
    if (!parsed.arguments.count(name))
      throw InputError(where + ": '" + request.kind + "' needs argument '" + name + "'");
  check_ids(parsed, where);
  // The residual loop's reports come as text, JSON or a self-contained HTML page.
  const bool report = spec->html_reply;
  if (const auto format = parsed.optional("format");
      format && *format != "text" && *format != "json" && !(report && *format == "html"))
    throw InputError(where + ": format '" + *format + "' is neither text nor json" +
                     (report ? " nor html" : ""));
  return parsed;
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    const auto item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!item.empty()) items.push_back(item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return items;
}

std::map<std::string, double> parse_references(const std::vector<std::string>& arguments) {
  std::map<std::string, double> out;
  for (const std::string& a : arguments) {
    const auto equals = a.find('=');
    if (equals == std::string::npos || equals == 0)
      throw InputError("reference '" + a + "': expected name=value, e.g. mass=1457.5");
    const std::string name = a.substr(0, equals);
    const std::string text = a.substr(equals + 1);
    const std::optional<double> value = input::parse_finite(text);
    if (!value) throw InputError("reference '" + a + "': '" + text + "' is not a finite number");
    if (!out.emplace(name, *value).second) throw InputError("reference '" + name + "' given twice");
  }
  return out;
}

int parse_rounds(const std::optional<std::string>& text) {
  if (!text) return 4;
  const std::optional<long long> rounds = input::parse_integer(*text);
  if (!rounds || *rounds < 0 || *rounds > 10) throw InputError("rounds '" + *text + "': an integer from 0 to 10");
  return static_cast<int>(*rounds);
}

int parse_part(const std::optional<std::string>& text) {
  if (!text) return 1;
  const std::optional<long long> part = input::parse_integer(*text);
  if (!part || *part < 1 || *part > 1000000)
    throw InputError("part '" + *text + "': an integer from 1");
  return static_cast<int>(*part);
}

bool parse_series(const std::optional<std::string>& text) {
  if (!text) return false;
  if (*text != "yes")
    throw InputError("series '" + *text + "': only 'yes' (the key's presence asks for it)");
  return true;
}

}  // namespace dynid::server
