#include "dynid/model/constants.hpp"

#include <cmath>

#include "dynid/error.hpp"

namespace dynid::model {
namespace {

thread_local ConstantProbe* active_probe = nullptr;

}  // namespace

ConstantProbe::ConstantProbe() : outer_(active_probe) {
  active_probe = this;
}

ConstantProbe::~ConstantProbe() {
  active_probe = outer_;
}

void ConstantProbe::record(ConstantUse use) {
  for (ConstantUse& u : uses_) {
    if (u.name != use.name) continue;
    if (use.required) u.required = true;
    if (u.meaning.empty()) u.meaning = use.meaning;
    if (!u.fallback) u.fallback = use.fallback;
    return;
  }
  uses_.push_back(std::move(use));
}

double ConstantReader::required(const std::string& name, const std::string& meaning) const {
  if (active_probe != nullptr) {
    active_probe->record({name, meaning, true, std::nullopt});
    return 1.0;
  }
  const std::optional<double> v = optional(name);
  if (!v)
    throw InputError("model '" + model_ + "': missing constant '" + name + "' (" + meaning + ")");
  return *v;
}

double ConstantReader::positive(const std::string& name, const std::string& meaning) const {
  const double v = required(name, meaning);
  if (v <= 0.0)
    throw InputError("model '" + model_ + "': constant '" + name + "' = " + std::to_string(v) +
                     " must be > 0 (" + meaning + ")");
  return v;
}

std::optional<double> ConstantReader::optional(const std::string& name) const {
  if (active_probe != nullptr) {
    active_probe->record({name, "", false, std::nullopt});
    return std::nullopt;
  }
  const auto it = constants_.find(name);
  if (it == constants_.end()) return std::nullopt;
  if (!std::isfinite(it->second))
    throw InputError("model '" + model_ + "': constant '" + name + "' is not finite");
  return it->second;
}

double ConstantReader::positive_or(const std::string& name, double fallback) const {
  if (active_probe != nullptr) {
    active_probe->record({name, "", false, fallback});
    return fallback;
  }
  const std::optional<double> v = optional(name);
  if (!v) return fallback;
  if (*v <= 0.0)
    throw InputError("model '" + model_ + "': constant '" + name + "' = " + std::to_string(*v) +
                     " must be > 0");
  return *v;
}

}  // namespace dynid::model
