#pragma once
// Constants: the named numbers of a vehicle profile that a model takes as known (wheel radius,
// axle distances a and b, air density, driveline efficiency, a weighed mass, hub positions...),
// SI units. Profiles, not code, describe a car: no model holds a car's numbers.
//
// ConstantReader reads them for one model: a missing required constant, a non-finite value or
// one out of its range throws InputError naming the model, the constant and why. Constants the
// model does not read are ignored (a profile serves several models).
#include <map>
#include <optional>
#include <string>

namespace dynid::model {

using Constants = std::map<std::string, double>;

class ConstantReader {
 public:
  ConstantReader(const Constants& constants, std::string model)
      : constants_(constants), model_(std::move(model)) {}

  /// A required constant (finite), `meaning` says what it is in the error message.
  double required(const std::string& name, const std::string& meaning) const;
  /// A required constant that must be > 0.
  double positive(const std::string& name, const std::string& meaning) const;
  /// An optional constant (finite if present).
  std::optional<double> optional(const std::string& name) const;
  /// An optional constant > 0 with a default.
  double positive_or(const std::string& name, double fallback) const;

 private:
  const Constants& constants_;
  std::string model_;
};

}  // namespace dynid::model
