#include "dynid/model/constants.hpp"

#include <cmath>

#include "dynid/error.hpp"

namespace dynid::model {

double ConstantReader::required(const std::string& name, const std::string& meaning) const {
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
  const auto it = constants_.find(name);
  if (it == constants_.end()) return std::nullopt;
  if (!std::isfinite(it->second))
    throw InputError("model '" + model_ + "': constant '" + name + "' is not finite");
  return it->second;
}

double ConstantReader::positive_or(const std::string& name, double fallback) const {
  const std::optional<double> v = optional(name);
  if (!v) return fallback;
  if (*v <= 0.0)
    throw InputError("model '" + model_ + "': constant '" + name + "' = " + std::to_string(*v) +
                     " must be > 0");
  return *v;
}

}  // namespace dynid::model
