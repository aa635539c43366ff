#include "dynid/model/stribeck_bank.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"

namespace dynid::model {

StribeckSpeedBank::StribeckSpeedBank(const Constants& constants, std::vector<double> candidates,
                                     std::vector<std::string> effects)
    : effects_(std::move(effects)) {
  if (candidates.empty()) throw InputError("Stribeck bank: no candidate speed");
  if (!enabled(effects_, effect::kStribeck)) effects_.insert(effects_.begin(), effect::kStribeck);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const double v = candidates[i];
    if (!std::isfinite(v) || v <= 0.0)
      throw InputError("Stribeck bank: candidate " + std::to_string(i) + " = " +
                       std::to_string(v) + " is not a positive speed");
    if (std::count(candidates.begin(), candidates.end(), v) > 1)
      throw InputError("Stribeck bank: candidate " + std::to_string(v) + " given twice");
    Constants c = constants;
    c["stribeck_speed"] = v;
    models_.push_back(std::make_unique<ClutchSlipModel>(c));
  }
  const auto n = static_cast<Eigen::Index>(models_.front()->parameters_with(effects_).size());
  accumulators_.assign(models_.size(), ls::Accumulator(n));
}

void StribeckSpeedBank::fold(const ChannelSet& channels) {
  // Build every candidate's rows before folding any, so a rejected set changes no state.
  std::vector<GroupRows> rows;
  for (const auto& m : models_) rows.push_back(m->rows(channels, effects_).front());
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (rows[i].W.rows() > 0) accumulators_[i].fold(rows[i].W, rows[i].y);
}

std::vector<double> StribeckSpeedBank::residual_norms() const {
  std::vector<double> out;
  for (const ls::Accumulator& a : accumulators_) out.push_back(ls::estimate(a).residual_norm);
  return out;
}

std::size_t StribeckSpeedBank::best() const {
  const std::vector<double> r = residual_norms();
  return static_cast<std::size_t>(std::min_element(r.begin(), r.end()) - r.begin());
}

}  // namespace dynid::model
