#include "dynid/model/model_needs.hpp"

#include <algorithm>

#include "dynid/model/registry.hpp"

namespace dynid::model {

ModelNeeds model_needs(const std::string& name) {
  ModelNeeds out;
  out.model = name;
  std::unique_ptr<Model> model;
  {
    ConstantProbe probe;  // the constructor reads every constant the model knows
    model = make_model(name, {});
    out.constants = probe.uses();
  }
  std::stable_partition(out.constants.begin(), out.constants.end(),
                        [](const ConstantUse& c) { return c.required; });
  out.channels = model->channels();
  std::stable_partition(out.channels.begin(), out.channels.end(),
                        [](const ChannelNeed& c) { return !c.optional; });
  out.parameters = model->parameters();
  out.effects = model->candidate_effects();
  return out;
}

std::vector<ModelNeeds> all_model_needs() {
  std::vector<ModelNeeds> out;
  for (const std::string& name : model_names()) out.push_back(model_needs(name));
  return out;
}

}  // namespace dynid::model
