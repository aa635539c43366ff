#include "model_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dynid/ls/accumulator.hpp"

namespace dynid::test {

double Sines::value(double t) const {
  double x = offset;
  for (std::size_t i = 0; i < amplitude.size(); ++i)
    x += amplitude[i] * std::sin(omega[i] * t + phase[i]);
  return x;
}

double Sines::derivative(double t) const {
  double x = 0.0;
  for (std::size_t i = 0; i < amplitude.size(); ++i)
    x += amplitude[i] * omega[i] * std::cos(omega[i] * t + phase[i]);
  return x;
}

Eigen::VectorXd Sines::values(const Eigen::VectorXd& t) const {
  return t.unaryExpr([this](double s) { return value(s); });
}

Eigen::VectorXd Sines::derivatives(const Eigen::VectorXd& t) const {
  return t.unaryExpr([this](double s) { return derivative(s); });
}

Eigen::VectorXd time_grid(double period, Eigen::Index samples) {
  return Eigen::VectorXd::LinSpaced(samples, 0.0, period * static_cast<double>(samples - 1));
}

namespace {
std::size_t index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << "no parameter " << name;
  return static_cast<std::size_t>(it - names.begin());
}
}  // namespace

double Identified::value(const std::string& name) const {
  return estimate.value(static_cast<Eigen::Index>(index_of(names, name)));
}

ls::ParameterStatus Identified::status(const std::string& name) const {
  return estimate.structure.status[index_of(names, name)];
}

const model::ParameterInfo& Identified::info(const std::string& name) const {
  return parameters.at(index_of(names, name));
}

Identified identify(const model::Model& m, const model::ChannelSet& channels,
                    const std::vector<std::string>& effects) {
  Identified out;
  out.parameters = m.parameters_with(effects);
  for (const model::ParameterInfo& p : out.parameters) out.names.push_back(p.name);
  ls::Accumulator acc(static_cast<Eigen::Index>(out.names.size()));
  for (const model::GroupRows& g : m.rows(channels, effects)) {
    EXPECT_EQ(g.W.cols(), static_cast<Eigen::Index>(out.names.size())) << g.group;
    if (g.W.rows() == 0) continue;
    acc.fold(g.W, g.y);
    out.rows += static_cast<std::size_t>(g.W.rows());
  }
  out.estimate = ls::estimate(acc);
  return out;
}

double relative_error(double estimate, double truth) {
  return std::abs(estimate - truth) / std::abs(truth);
}

void expect_within_bounds(const Identified& id, const std::map<std::string, double>& truth) {
  for (const auto& [name, value] : truth) {
    const model::ParameterInfo& p = id.info(name);
    EXPECT_TRUE(p.within_bounds(value)) << name << " = " << value << " is outside " << p.bounds_text();
  }
}

void expect_recovered(const Identified& id, const std::map<std::string, double>& truth,
                      double tolerance) {
  for (const auto& [name, value] : truth)
    EXPECT_LT(relative_error(id.value(name), value), tolerance)
        << name << ": " << id.value(name) << " vs " << value;
  expect_within_bounds(id, truth);
}

}  // namespace dynid::test
