#pragma once
// Test support for the models: smooth excitation signals with analytic derivatives, and
// identification of a model's rows with the least-squares core.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "dynid/ls/estimate.hpp"
#include "dynid/model/model.hpp"

namespace dynid::test {

/// x(t) = offset + sum_i amplitude_i sin(omega_i t + phase_i), with its exact derivative.
struct Sines {
  double offset = 0.0;
  std::vector<double> amplitude, omega, phase;
  double value(double t) const;
  double derivative(double t) const;
  Eigen::VectorXd values(const Eigen::VectorXd& t) const;
  Eigen::VectorXd derivatives(const Eigen::VectorXd& t) const;
};

/// t_k = k * period, k = 0..samples-1.
Eigen::VectorXd time_grid(double period, Eigen::Index samples);

struct Identified {
  ls::Estimate estimate;
  std::vector<std::string> names;  ///< parameters_with(effects), column order
  std::vector<model::ParameterInfo> parameters;  ///< the same, in full (bounds)
  std::size_t rows = 0;
  /// Value of a parameter by name (fails the test if absent).
  double value(const std::string& name) const;
  ls::ParameterStatus status(const std::string& name) const;
  /// The parameter's description by name (fails the test if absent).
  const model::ParameterInfo& info(const std::string& name) const;
};

/// Rows of all groups stacked in one accumulator (unweighted), then ls::estimate.
Identified identify(const model::Model& m, const model::ChannelSet& channels,
                    const std::vector<std::string>& effects = {});

double relative_error(double estimate, double truth);

/// Every truth value within the bounds its parameter declares: the data of a recovery test is
/// made with the model's own equations from physical values, so a truth out of a bound means
/// the bound is wrong (it would call a correct estimate impossible).
void expect_within_bounds(const Identified& id, const std::map<std::string, double>& truth);

/// Each parameter recovered to `tolerance` relative, and its truth within its bounds.
void expect_recovered(const Identified& id, const std::map<std::string, double>& truth,
                      double tolerance = 1e-6);

}  // namespace dynid::test
