#pragma once
// What a model needs and gives, by name, without a vehicle profile: the channels it reads
// (required and optional), the constants it reads (from its constructor, through
// ConstantProbe: constants.hpp), the parameters it identifies and its candidate effects with the
// channels each adds. What `dynid models` and `dynid effects` print, and the table of
// docs/PROFILES.md ("What each model needs") is made from (tests/docs checks it).
//
// Contract: model_needs() throws InputError for an unknown name (listing the known ones), as
// make_model() does; otherwise it never throws and has no effect outside the calling thread.
#include <string>
#include <vector>

#include "dynid/model/constants.hpp"
#include "dynid/model/model.hpp"

namespace dynid::model {

struct ModelNeeds {
  std::string model;
  std::vector<ChannelNeed> channels;      ///< required first, then optional (an effect's)
  std::vector<ConstantUse> constants;     ///< required first, then optional
  std::vector<ParameterInfo> parameters;  ///< without any effect
  std::vector<Effect> effects;            ///< the model's physical candidates
};

ModelNeeds model_needs(const std::string& model);

/// Every registered model's needs, in model_names() order.
std::vector<ModelNeeds> all_model_needs();

}  // namespace dynid::model
