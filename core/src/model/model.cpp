#include "dynid/model/model.hpp"

#include <array>
#include <charconv>
#include <cmath>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"

namespace dynid::model {
namespace {

// The shortest text that reads back as `x` ("0", "2", "0.5", "1e+06").
std::string shortest(double x) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  return {buffer.data(), result.ptr};
}

}  // namespace

bool ParameterInfo::within_bounds(double value) const {
  if (std::isnan(value)) return true;
  if (lower && (lower_inclusive ? value < *lower : value <= *lower)) return false;
  if (upper && (upper_inclusive ? value > *upper : value >= *upper)) return false;
  return true;
}

std::string ParameterInfo::bounds_text() const {
  if (lower && upper)
    return (lower_inclusive ? "[" : "(") + shortest(*lower) + ", " + shortest(*upper) +
           (upper_inclusive ? "]" : ")");
  if (lower) return (lower_inclusive ? ">= " : "> ") + shortest(*lower);
  if (upper) return (upper_inclusive ? "<= " : "< ") + shortest(*upper);
  return "";
}

std::vector<ParameterInfo> Model::parameters_with(const std::vector<std::string>& effects) const {
  std::vector<ParameterInfo> out = parameters();
  const std::vector<Effect> candidates = candidate_effects();
  for (const std::string& name : effects) {
    if (is_dictionary_effect(name)) {
      const Effect e = dictionary_effect(name, groups());
      out.insert(out.end(), e.parameters.begin(), e.parameters.end());
      continue;
    }
    bool found = false;
    for (const Effect& e : candidates) {
      if (e.name != name) continue;
      out.insert(out.end(), e.parameters.begin(), e.parameters.end());
      found = true;
    }
    if (!found) throw InputError("model '" + this->name() + "': unknown effect '" + name + "'");
  }
  return out;
}

RowReach Model::reach(double) const {
  return {};
}

bool Model::can_run_on(const ChannelSet& channels) const {
  for (const ChannelNeed& need : this->channels())
    if (!need.optional && !channels.has(need.name)) return false;
  return true;
}

}  // namespace dynid::model
