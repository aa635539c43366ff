#include "dynid/dds/protocol.hpp"

#include <algorithm>

namespace dynid::dds::protocol {
namespace {

bool listed(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

bool RequestKind::takes(const std::string& argument) const {
  return listed(required, argument) || listed(optional, argument);
}

bool RequestKind::is_repeatable(const std::string& argument) const {
  return listed(repeatable, argument);
}

const std::vector<RequestKind>& request_kinds() {
  static const std::vector<RequestKind> kinds{
      {"add-effect",
       {"vehicle", "run", "model", "effect"},
       {"effects", "reference", "series", "format"},
       {"reference"},
       true},
      {"base", {"vehicle", "run", "model"}, {"format"}, {}, false},
      {"close", {"vehicle", "run"}, {"format"}, {}, false},
      {"consistency", {"vehicle", "run"}, {"reference", "format"}, {"reference"}, false},
      {"estimate", {"vehicle"}, {"run", "model", "format"}, {}, false},
      {"excitation", {"vehicle"}, {"run", "format"}, {}, false},
      {"export", {"vehicle", "run"}, {"model", "effects", "part"}, {}, false},
      {"fleet", {"model", "shared", "vehicles"}, {"format"}, {"shared"}, false},
      {"iv", {"vehicle", "run", "model"}, {"effects", "format"}, {}, false},
      {"pooled", {"vehicle", "run"}, {"model", "format"}, {"run"}, false},
      {"reprocess", {"vehicle", "run", "model"}, {"effects", "format"}, {}, false},
      {"residual", {"vehicle", "run", "model"}, {"effects", "candidates", "format"}, {}, true},
      {"runs", {"vehicle"}, {"format"}, {}, false},
      {"simex", {"vehicle", "run", "model"}, {"effects", "format"}, {}, false},
      {"status", {}, {"format"}, {}, false},
      {"trace",
       {"vehicle", "run", "model"},
       {"effects", "reference", "rounds", "series", "format"},
       {"reference"},
       true},
      {"vehicles", {}, {"format"}, {}, false},
  };
  return kinds;
}

const RequestKind* find_request_kind(const std::string& name) {
  for (const RequestKind& kind : request_kinds())
    if (kind.name == name) return &kind;
  return nullptr;
}

std::string request_kind_names() {
  std::string names;
  for (const RequestKind& kind : request_kinds()) names += (names.empty() ? "" : ", ") + kind.name;
  return names;
}

}  // namespace dynid::dds::protocol
