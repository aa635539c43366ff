#pragma once
// RowModel: the machinery shared by the models, whose rows are built sample by sample.
//
// A concrete model supplies (1) a row function that, for a sample k and an equation group,
// fills its parameter columns and measured side or declines the row (masking: clutch not
// slipping, wrong gear, braking...), and (2) its candidate effects, each a column function.
// RowModel::rows() then: checks that every non-optional channel is present and every channel
// used has the catalogue's SI unit (docs/CHANNELS.md), resolves the enabled effects (the model's
// own and the generic dictionary, effects.hpp), skips invalid samples, appends the effects'
// columns in the order given, and throws InputError naming model, group and sample if a row
// would carry a NaN/Inf (never a silently wrong estimate). Channels are looked up once per call.
#include <functional>
#include <string>
#include <vector>

#include "dynid/model/model.hpp"

namespace dynid::model {

class RowModel : public Model {
 public:
  std::vector<Effect> candidate_effects() const final;
  std::vector<GroupRows> rows(const ChannelSet& channels,
                              const std::vector<std::string>& effects = {}) const final;
  std::vector<GroupRows> rows_at(const ChannelSet& channels,
                                 const std::vector<Eigen::Index>& samples,
                                 const std::vector<std::string>& effects = {}) const final;

  /// Fills `w` (parameters().size() entries, zeroed) and `y` for group `group` at sample k;
  /// returns false to leave the row out. rows() calls it for every group of a sample, in group
  /// order, before the next sample, so a bound function may keep what its groups share for the
  /// last sample (the body's regressor) instead of computing it once per group.
  using RowFn = std::function<bool(Eigen::Index k, std::size_t group, double* w, double& y)>;
  /// Fills an effect's columns (its parameters().size() entries, zeroed); false leaves the row
  /// out (e.g. a lag reaching an invalid sample).
  using ColumnFn = std::function<bool(Eigen::Index k, std::size_t group, double* out)>;
  struct EffectDefinition {
    Effect info;
    /// Binds the effect's channels once per rows() call.
    std::function<ColumnFn(const ChannelSet&)> bind;
  };

 protected:
  virtual std::vector<EffectDefinition> effect_definitions() const = 0;
  /// Binds the model's channels once per rows() call. `effects` are the enabled effects'
  /// names: some change the masking (brake drag lets braking rows in).
  virtual RowFn bind(const ChannelSet& channels, const std::vector<std::string>& effects) const = 0;

 private:
  void check_channels(const ChannelSet& channels) const;
  std::vector<EffectDefinition> resolve(const ChannelSet& channels,
                                        const std::vector<std::string>& effects) const;
  template <typename Samples>
  std::vector<GroupRows> build(const ChannelSet& channels, const Samples& samples,
                               const std::vector<std::string>& effects) const;
};

/// True when `name` is among the enabled `effects`.
bool enabled(const std::vector<std::string>& effects, const std::string& name);

}  // namespace dynid::model
