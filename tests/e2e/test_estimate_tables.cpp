// The publication rule on the server's tables (server/estimate_tables.hpp: apply_publication,
// residual/publication.hpp), on a least-squares table of two parameters and fits built by hand.
// Where IV replaced least squares, SIMEX takes its rows only when Hausman's comparison lets it
// stand; the bias test's line says which way; least squares stays beside either.
#include <gtest/gtest.h>

#include <cmath>

#include "dynid/dds/estimate_table.hpp"
#include "dynid/ls/equation_groups.hpp"
#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/simex.hpp"
#include "dynid/server/estimate_tables.hpp"

namespace dynid::server {
namespace {

std::vector<model::ParameterInfo> parameters() {
  model::ParameterInfo a, b;
  a.name = "a";
  b.name = "b";
  a.unit = b.unit = "-";
  return {a, b};
}

// y = 1.0 x1 + 2.0 x2 with a small deterministic disturbance: both columns well excited.
ls::WeightedEstimate least_squares() {
  ls::EquationGroups groups(2, {"rows"});
  Eigen::MatrixXd w(60, 2);
  Eigen::VectorXd y(60);
  for (Eigen::Index i = 0; i < w.rows(); ++i) {
    const auto t = static_cast<double>(i);
    w(i, 0) = 1.0 + std::sin(0.3 * t);
    w(i, 1) = std::cos(0.17 * t);
    y(i) = w(i, 0) + 2.0 * w(i, 1) + 0.01 * std::sin(1.7 * t);
  }
  groups.fold(0, w, y);
  return groups.estimate();
}

residual::IvFit iv_rejecting_least_squares() {
  residual::IvFit iv;
  iv.model = "m";
  iv.parameters = parameters();
  iv.value = Eigen::Vector2d(1.02, 2.04);
  iv.hac_std = Eigen::Vector2d(0.02, 0.04);
  iv.difference_std = Eigen::Vector2d(0.015, 0.03);
  iv.dwh.rejects = true;
  return iv;
}

residual::SimexFit simex_at(const Eigen::Vector2d& value) {
  residual::SimexFit simex;
  simex.model = "m";
  simex.parameters = parameters();
  simex.contributing = {"vx"};
  simex.value = value;
  simex.std = Eigen::Vector2d(0.01, 0.02);
  simex.ls_value = Eigen::Vector2d(1.0, 2.0);
  // The differences' std: sqrt(0.015^2 + 2 x 0.002^2) = 0.0153 and sqrt(0.03^2 + 2 x 0.004^2) = 0.0305.
  simex.monte_carlo_std = simex.level_std = Eigen::Vector2d(0.002, 0.004);
  return simex;
}

dds::EstimateTable published(const residual::SimexFit& simex, const residual::IvFit* iv) {
  const ls::WeightedEstimate estimate = least_squares();
  dds::EstimateTable table = table_of("car", "run", "m", parameters(), estimate);
  apply_publication(table, parameters(), estimate, iv, &simex, 7);
  return table;
}

TEST(EstimateTables, SimexAgreeingWithIvTakesIvsRowsWithLeastSquaresBeside) {
  const residual::IvFit iv = iv_rejecting_least_squares();
  const residual::SimexFit simex = simex_at(Eigen::Vector2d(1.021, 2.03));
  const dds::EstimateTable table = published(simex, &iv);
  EXPECT_EQ(table.estimator, dds::kSimex);
  EXPECT_EQ(table.bias_test.rfind(iv.statement(), 0), 0u) << table.bias_test;
  EXPECT_NE(table.bias_test.find("SIMEX published"), std::string::npos) << table.bias_test;
  const ls::WeightedEstimate estimate = least_squares();
  for (std::size_t k = 0; k < 2; ++k) {
    const auto j = static_cast<Eigen::Index>(k);
    EXPECT_EQ(table.parameters[k].value, simex.value(j));
    EXPECT_EQ(table.parameters[k].standard_deviation, simex.std(j));
    EXPECT_EQ(table.parameters[k].least_squares_value, estimate.estimate.value(j));
  }
}

TEST(EstimateTables, SimexDisagreeingWithIvLeavesIvsRowsAndSaysWhy) {
  const residual::IvFit iv = iv_rejecting_least_squares();
  // b: |2.04 - 1.90| / 0.0305 = 4.6, beyond the 0.5 % bound (2.81).
  const dds::EstimateTable table = published(simex_at(Eigen::Vector2d(1.02, 1.90)), &iv);
  EXPECT_EQ(table.estimator, dds::kInstrumentalVariables);
  EXPECT_NE(table.bias_test.find("IV kept"), std::string::npos) << table.bias_test;
  EXPECT_EQ(table.parameters[1].value, iv.value(1));
  EXPECT_EQ(table.parameters[1].standard_deviation, iv.hac_std(1));
}

TEST(EstimateTables, AnIvFitOfOtherColumnsIsIgnored) {
  residual::IvFit iv = iv_rejecting_least_squares();
  iv.parameters[1].name = "c";  // another effect set's columns
  const ls::WeightedEstimate estimate = least_squares();
  dds::EstimateTable table = table_of("car", "run", "m", parameters(), estimate);
  apply_publication(table, parameters(), estimate, &iv, nullptr, 7);
  EXPECT_EQ(table.estimator, dds::kLeastSquares);
  EXPECT_EQ(table.bias_test, "");
  EXPECT_EQ(table.parameters[1].value, estimate.estimate.value(1));
}

}  // namespace
}  // namespace dynid::server
