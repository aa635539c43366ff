#include "dynid/ingest/model_channels.hpp"

#include <algorithm>

#include "dynid/model/effects.hpp"

namespace dynid::ingest {
namespace {

void add_once(std::vector<std::string>& names, const std::string& name) {
  if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
}

bool announced(const RunAnnouncement& a, std::string_view name) {
  return std::any_of(a.channels.begin(), a.channels.end(),
                     [&](const ChannelSpec& c) { return c.name == name; });
}

// The channels of the enabled effects: each is needed, even where the model's own need of it
// is optional (an effect reads it in every row).
std::vector<std::string> effect_channels(const model::Model& m, const ModelSpec& spec) {
  std::vector<std::string> out;
  const std::vector<model::Effect> own = m.candidate_effects();
  for (const std::string& e : spec.effects) {
    const auto it =
        std::find_if(own.begin(), own.end(), [&](const model::Effect& x) { return x.name == e; });
    if (it != own.end())
      for (const std::string& c : it->channels) add_once(out, c);
    else if (model::is_dictionary_effect(e))
      for (const std::string& c : model::dictionary_effect(e, m.groups()).channels)
        add_once(out, c);
  }
  return out;
}

}  // namespace

std::vector<std::string> channels_read(const model::Model& model, const ModelSpec& spec) {
  std::vector<std::string> out;
  for (const model::ChannelNeed& need : model.channels()) add_once(out, need.name);
  for (const std::string& c : effect_channels(model, spec)) add_once(out, c);
  return out;
}

bool run_provides(const RunAnnouncement& announcement, std::string_view channel) {
  if (announced(announcement, channel)) return true;
  return channel.substr(0, 2) == "d_" && announced(announcement, channel.substr(2));
}

ChannelGaps channel_gaps(const model::Model& model, const ModelSpec& spec,
                         const std::function<bool(const std::string&)>& provided) {
  const std::vector<std::string> by_effects = effect_channels(model, spec);
  const auto needed_by_effect = [&](const std::string& c) {
    return std::find(by_effects.begin(), by_effects.end(), c) != by_effects.end();
  };
  ChannelGaps gaps;
  for (const model::ChannelNeed& need : model.channels()) {
    if (provided(need.name)) continue;
    add_once(need.optional && !needed_by_effect(need.name) ? gaps.optional_absent : gaps.missing,
             need.name);
  }
  for (const std::string& c : by_effects)
    if (!provided(c)) add_once(gaps.missing, c);
  return gaps;
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out;
}

}  // namespace dynid::ingest
