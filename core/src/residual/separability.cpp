#include "dynid/residual/separability.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

namespace dynid::residual {
namespace {

std::string separating_manoeuvre(const model::Model& model, const CandidateScore& c, const std::string& parameter) {
  for (const model::Effect& e : model.candidate_effects())
    if (e.name == c.effect && !e.separated_by.empty()) return e.separated_by;
  return "a run in which " + c.effect + "'s column varies apart from the column of " + parameter;
}

// The declared parameter that the undetectable effect moves most, in its standard deviations.
std::optional<Inseparable> worst_shift(const model::Model& model, const ScreenResult& screen, const CandidateScore& c) {
  const ls::Estimate& e = screen.fit.estimate;
  Inseparable out;
  for (std::size_t j = 0; j < c.alias.size() && j < screen.fit.parameters.size(); ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    const double std_j = e.standard_deviation(i);
    if (!std::isfinite(std_j) || std_j <= 0.0 || !std::isfinite(e.value(i))) continue;
    const double shift = c.alias[j] * (c.significant ? c.coefficient : c.detectable);
    if (std::abs(shift) / std_j <= std::abs(out.shift_in_std)) continue;
    out.parameter = screen.fit.parameters[j].name;
    out.shift = shift;
    out.shift_in_std = shift / std_j;
    out.shift_relative = e.value(i) != 0.0 ? shift / std::abs(e.value(i)) : 0.0;
  }
  if (std::abs(out.shift_in_std) <= kShiftInStd) return std::nullopt;
  out.separated_by = separating_manoeuvre(model, c, out.parameter);
  return out;
}

}  // namespace

std::string Inseparable::statement() const {
  char buf[512];
  if (!identifiable) {
    std::snprintf(buf, sizeof buf, "%s cannot be separated on this run: its column is a combination of the declared ones; to separate it: %s",
                  effect.c_str(), separated_by.c_str());
    return buf;
  }
  const std::string size = significant ? "its fitted %.3g %s, significant under the noise floor, would"
                                        : "up to %.3g %s would pass unseen (80 %% power) and";
  const std::string pattern = "%s cannot be separated on this run: " + size +
                              " move %s by %+.3g (%+.1f %%, %.1f std); to separate it: %s";
  std::snprintf(buf, sizeof buf, pattern.c_str(), effect.c_str(), significant ? detectable : std::abs(detectable),
                unit.c_str(), parameter.c_str(), shift, 100.0 * shift_relative, std::abs(shift_in_std),
                separated_by.c_str());
  return buf;
}

std::vector<Inseparable> inseparable_effects(const model::Model& model, const ScreenResult& screen,
                                             const std::string& accepted) {
  std::vector<Inseparable> out;
  for (const CandidateScore& c : screen.candidates) {
    if (c.kind != CandidateKind::kPhysics || !c.evaluated || c.effect == accepted || c.columns != 1) continue;
    if (c.significant && !accepted.empty()) continue;  // a rival of the accepted one, in the ranking
    std::optional<Inseparable> found;
    if (!c.testable) {
      found = Inseparable{};
      found->identifiable = false;
      found->separated_by = separating_manoeuvre(model, c, "every declared parameter");
    } else {
      found = worst_shift(model, screen, c);
    }
    if (!found) continue;
    found->effect = c.effect;
    found->description = c.description;
    found->significant = c.significant;
    found->detectable = c.significant ? c.coefficient : c.detectable;
    found->unit = c.coefficient_unit;
    out.push_back(std::move(*found));
  }
  std::stable_sort(out.begin(), out.end(), [](const Inseparable& a, const Inseparable& b) {
    return a.identifiable && b.identifiable ? std::abs(a.shift_in_std) > std::abs(b.shift_in_std) : a.identifiable < b.identifiable;
  });
  return out;
}

}  // namespace dynid::residual
