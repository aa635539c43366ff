#include "dynid/model/row_model.hpp"

#include <algorithm>
#include <cmath>
#include <ranges>

#include "dictionary.hpp"
#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"

namespace dynid::model {

bool enabled(const std::vector<std::string>& effects, const std::string& name) {
  return std::find(effects.begin(), effects.end(), name) != effects.end();
}

std::vector<Effect> RowModel::candidate_effects() const {
  std::vector<Effect> out;
  for (EffectDefinition& d : effect_definitions()) out.push_back(std::move(d.info));
  return out;
}

void RowModel::check_channels(const ChannelSet& channels) const {
  for (const ChannelNeed& need : this->channels()) {
    if (!channels.has(need.name)) {
      if (need.optional) continue;
      throw InputError("model '" + name() + "': missing channel '" + need.name + "' (" +
                       need.unit + ")");
    }
    if (channels.unit(need.name) != need.unit)
      throw InputError("model '" + name() + "': channel '" + need.name + "' is in '" +
                       channels.unit(need.name) + "', expected '" + need.unit + "'");
  }
}

std::vector<RowModel::EffectDefinition> RowModel::resolve(
    const ChannelSet& channels, const std::vector<std::string>& effects) const {
  std::vector<EffectDefinition> own = effect_definitions();
  std::vector<EffectDefinition> out;
  for (std::size_t i = 0; i < effects.size(); ++i) {
    const std::string& e = effects[i];
    if (std::find(effects.begin(), effects.begin() + static_cast<std::ptrdiff_t>(i), e) !=
        effects.begin() + static_cast<std::ptrdiff_t>(i))
      throw InputError("model '" + name() + "': effect '" + e + "' enabled twice");
    const auto it = std::find_if(own.begin(), own.end(),
                                 [&](const EffectDefinition& d) { return d.info.name == e; });
    if (it != own.end()) {
      out.push_back(*it);
    } else if (is_dictionary_effect(e)) {
      out.push_back(detail::dictionary_definition(e, groups()));
    } else {
      std::string known;
      for (const EffectDefinition& d : own) known += " " + d.info.name;
      throw InputError("model '" + name() + "': unknown effect '" + e +
                       "' (candidates:" + known + ", or dict:<op>:<channel>)");
    }
    for (const std::string& c : out.back().info.channels)
      if (!channels.has(c))
        throw InputError("model '" + name() + "': effect '" + e + "' needs channel '" + c + "'");
  }
  return out;
}

namespace {

struct Bound {
  std::vector<RowModel::ColumnFn> columns;
  std::vector<std::size_t> widths;
};

// One group's rows as they are built: row-major, each row built in place at the end.
struct GroupBuffer {
  std::vector<double> data;
  std::vector<double> ys;
  std::vector<Eigen::Index> kept;
};

// Rows of every group at `samples` (a range of increasing sample indices), sample by sample,
// every group of a sample before the next sample: a model computing what its groups share
// (the body's 6 x 10 regressor) does it once per sample (RowModel::RowFn).
template <typename Samples>
std::vector<GroupRows> collect(const std::string& model, const std::vector<std::string>& groups,
                               const ChannelSet& channels, const Samples& samples,
                               const RowModel::RowFn& row, const Bound& effects,
                               std::size_t base_width, std::size_t width) {
  // Room for a streaming window's rows up front; a whole record's grow as they come (many may
  // be masked out, so its sample count would over-reserve).
  const std::size_t most = std::min<std::size_t>(std::ranges::size(samples), 4096);
  std::vector<GroupBuffer> buffers(groups.size());
  for (GroupBuffer& b : buffers) {
    b.data.reserve(most * width);
    b.ys.reserve(most);
    b.kept.reserve(most);
  }
  for (const Eigen::Index k : samples) {
    if (!channels.valid(k)) continue;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      GroupBuffer& b = buffers[g];
      const std::size_t at = b.data.size();
      b.data.resize(at + width, 0.0);
      double* w = b.data.data() + at;
      double y = 0.0;
      bool keep = row(k, g, w, y);
      std::size_t offset = base_width;
      for (std::size_t e = 0; keep && e < effects.columns.size(); ++e) {
        keep = effects.columns[e](k, g, w + offset);
        offset += effects.widths[e];
      }
      if (!keep) {
        b.data.resize(at);
        continue;
      }
      const bool finite =
          std::isfinite(y) && std::all_of(w, w + width, [](double v) { return std::isfinite(v); });
      if (!finite)
        throw InputError("model '" + model + "': group '" + groups[g] +
                         "' has a non-finite row at sample " + std::to_string(k) +
                         " (mark bad samples invalid)");
      b.ys.push_back(y);
      b.kept.push_back(k);
    }
  }
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<GroupRows> out;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    GroupBuffer& b = buffers[g];
    const auto m = static_cast<Eigen::Index>(b.ys.size());
    out.push_back({groups[g], Eigen::Map<const RowMajor>(b.data.data(), m, static_cast<Eigen::Index>(width)),
                   Eigen::Map<const Eigen::VectorXd>(b.ys.data(), m), std::move(b.kept)});
  }
  return out;
}

// InputError unless `samples` are increasing indices of a set of `count` samples.
void check_selection(const std::string& model, const std::vector<Eigen::Index>& samples,
                     Eigen::Index count) {
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Eigen::Index k = samples[i];
    if (k < 0 || k >= count)
      throw InputError("model '" + model + "': selected sample " + std::to_string(k) +
                       " (position " + std::to_string(i) + ") is outside the " +
                       std::to_string(count) + " samples");
    if (i > 0 && k <= samples[i - 1])
      throw InputError("model '" + model + "': selected samples are not increasing at position " +
                       std::to_string(i) + " (" + std::to_string(samples[i - 1]) + " then " +
                       std::to_string(k) + ")");
  }
}

}  // namespace

template <typename Samples>
std::vector<GroupRows> RowModel::build(const ChannelSet& channels, const Samples& samples,
                                       const std::vector<std::string>& effects) const {
  check_channels(channels);
  const std::vector<EffectDefinition> defs = resolve(channels, effects);
  const RowFn row = bind(channels, effects);
  Bound bound;
  const std::size_t base_width = parameters().size();
  std::size_t width = base_width;
  for (const EffectDefinition& d : defs) {
    bound.columns.push_back(d.bind(channels));
    bound.widths.push_back(d.info.parameters.size());
    width += d.info.parameters.size();
  }
  return collect(name(), groups(), channels, samples, row, bound, base_width, width);
}

std::vector<GroupRows> RowModel::rows(const ChannelSet& channels,
                                      const std::vector<std::string>& effects) const {
  return build(channels, std::views::iota(Eigen::Index{0}, channels.samples()), effects);
}

std::vector<GroupRows> RowModel::rows_at(const ChannelSet& channels,
                                         const std::vector<Eigen::Index>& samples,
                                         const std::vector<std::string>& effects) const {
  check_selection(name(), samples, channels.samples());
  return build(channels, samples, effects);
}

}  // namespace dynid::model
