#pragma once
// Constants: the named numbers of a vehicle profile that a model takes as known (wheel radius,
// axle distances a and b, air density, driveline efficiency, a weighed mass, hub positions...),
// SI units. Profiles, not code, describe a car: no model holds a car's numbers.
//
// ConstantReader reads them for one model: a missing required constant, a non-finite value or
// one out of its range throws InputError naming the model, the constant and why. Constants the
// model does not read are ignored (a profile serves several models).
//
// ConstantProbe lists what a model reads without a profile (model_needs.hpp): while one is alive
// on a thread, every ConstantReader of that thread records each constant it is asked for, and
// answers a required one with 1 (finite and > 0, so the model's constructor goes on to the next).
// The models' constructors are then the one home of which constants each model reads.
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace dynid::model {

using Constants = std::map<std::string, double>;

/// One constant a model reads.
struct ConstantUse {
  std::string name;
  std::string meaning;             ///< what it is (required constants say so), may be ""
  bool required = false;           ///< false: optional
  std::optional<double> fallback;  ///< the value an optional constant takes when absent
};

/// Records the constants the ConstantReaders of this thread are asked for, while alive (above).
class ConstantProbe {
 public:
  ConstantProbe();
  ~ConstantProbe();
  ConstantProbe(const ConstantProbe&) = delete;
  ConstantProbe& operator=(const ConstantProbe&) = delete;
  /// Each constant once, in the order first asked; a constant asked as optional and later as
  /// required is required.
  const std::vector<ConstantUse>& uses() const { return uses_; }
  void record(ConstantUse use);

 private:
  std::vector<ConstantUse> uses_;
  ConstantProbe* outer_;
};

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
