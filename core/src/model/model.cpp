#include "dynid/model/model.hpp"

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"

namespace dynid::model {

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
