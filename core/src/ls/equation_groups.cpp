#include "dynid/ls/equation_groups.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "dynid/error.hpp"

namespace dynid::ls {

EquationGroups::EquationGroups(Eigen::Index parameter_count, std::vector<std::string> names,
                               Precision precision)
    : names_(std::move(names)) {
  if (names_.empty()) throw InputError("equation groups: at least one group is needed");
  std::set<std::string> seen;
  for (const auto& name : names_) {
    if (name.empty()) throw InputError("equation groups: a group name is empty");
    if (!seen.insert(name).second)
      throw InputError("equation groups: duplicate group '" + name + "'");
  }
  groups_.assign(names_.size(), Accumulator(parameter_count, precision));
}

std::size_t EquationGroups::index_of(const std::string& name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  if (it == names_.end()) throw InputError("equation groups: unknown group '" + name + "'");
  return static_cast<std::size_t>(it - names_.begin());
}

void EquationGroups::fold(std::size_t group, const Eigen::Ref<const Eigen::MatrixXd>& W,
                          const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (group >= groups_.size())
    throw InputError("equation groups: group index " + std::to_string(group) + " out of range");
  groups_[group].fold(W, y);
}

WeightedEstimate EquationGroups::estimate(const EstimateOptions& options) const {
  std::vector<GroupStatistics> stats(groups_.size());
  double largest_weight = 0.0;
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    stats[g].name = names_[g];
    stats[g].rows = groups_[g].row_count();
    if (stats[g].rows == 0) continue;
    const Estimate own = ls::estimate(groups_[g], options);
    stats[g].base_count = own.structure.rank();
    stats[g].sigma = own.sigma;
    if (std::isfinite(own.sigma) && own.sigma > 0.0) {
      stats[g].weight = 1.0 / own.sigma;
      largest_weight = std::max(largest_weight, stats[g].weight);
    }
  }
  Accumulator weighted(groups_.front().parameter_count());
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    if (stats[g].rows == 0) continue;
    if (stats[g].weight == 0.0) {
      stats[g].weight = largest_weight > 0.0 ? largest_weight : 1.0;
      stats[g].weight_from_fallback = true;
    }
    Accumulator scaled = groups_[g];
    scaled.scale_rows(stats[g].weight);
    weighted.merge(scaled);
  }
  if (weighted.row_count() == 0) throw InputError("equation groups: no group has rows");

  WeightedEstimate out{ls::estimate(weighted, options), std::move(stats), weighted};
  // Per-group unweighted residual at the global solution (dependent/eliminated columns: 0).
  const Eigen::VectorXd x =
      out.estimate.value.unaryExpr([](double v) { return std::isnan(v) ? 0.0 : v; });
  for (std::size_t g = 0; g < groups_.size(); ++g)
    if (out.groups[g].rows > 0)
      out.groups[g].residual_rms =
          groups_[g].residual_norm_at(x) / std::sqrt(static_cast<double>(out.groups[g].rows));
  return out;
}

}  // namespace dynid::ls
