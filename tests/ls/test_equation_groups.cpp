// DYCARO's weighted least squares: weights 1/sigma_j from each group's own fit, global solution
// from the stacked scaled R_j, equal to an explicit weighted batch solve of all rows.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <random>

#include "batch_reference.hpp"
#include "dynid/error.hpp"
#include "dynid/ls/equation_groups.hpp"

namespace dynid::test {
namespace {

struct Group {
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
};

// Group g uses the first `used` of 5 parameters (the others' columns are zero) and has its own
// noise level.
Group make_group(std::mt19937_64& rng, Eigen::Index rows, Eigen::Index used, double noise) {
  std::normal_distribution<double> gauss;
  Eigen::VectorXd x(5);
  x << 1200.0, 0.35, -4.0, 2.5, 60.0;
  Group g{Eigen::MatrixXd::Zero(rows, 5), Eigen::VectorXd(rows)};
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index j = 0; j < used; ++j) g.W(i, j) = gauss(rng) * (1.0 + j);
  g.y = g.W * x;
  for (Eigen::Index i = 0; i < rows; ++i) g.y(i) += noise * gauss(rng);
  return g;
}

// sigma_j from the group's own minimum-norm batch fit, with n_bj = rank(W_j).
double own_sigma(const Group& g) {
  const auto cod = g.W.completeOrthogonalDecomposition();
  const double rss = (g.W * cod.solve(g.y) - g.y).squaredNorm();
  return std::sqrt(rss / static_cast<double>(g.W.rows() - cod.rank()));
}

TEST(EquationGroups, WeightedEstimateEqualsExplicitWeightedBatch) {
  std::mt19937_64 rng(2003);
  const std::vector<Group> groups{make_group(rng, 300, 5, 0.01), make_group(rng, 200, 3, 1.0),
                                  make_group(rng, 250, 5, 0.2)};
  ls::EquationGroups eg(5, {"x", "y", "yaw"});
  Eigen::MatrixXd W_all(750, 5);
  Eigen::VectorXd y_all(750);
  Eigen::Index row = 0;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    for (Eigen::Index first = 0; first < groups[g].W.rows(); first += 64) {
      const Eigen::Index count = std::min<Eigen::Index>(64, groups[g].W.rows() - first);
      eg.fold(g, groups[g].W.middleRows(first, count), groups[g].y.segment(first, count));
    }
    const double sigma = own_sigma(groups[g]);
    W_all.middleRows(row, groups[g].W.rows()) = groups[g].W / sigma;
    y_all.segment(row, groups[g].W.rows()) = groups[g].y / sigma;
    row += groups[g].W.rows();
  }
  const ls::WeightedEstimate we = eg.estimate();
  const BatchSolution batch = batch_solve(W_all, y_all);
  EXPECT_LT(relative_error(we.estimate.value, batch.x), 1e-12);
  EXPECT_LT(relative_error(we.estimate.standard_deviation, batch.standard_deviation), 1e-12);
  EXPECT_NEAR(we.estimate.sigma, batch.sigma, 1e-12 * batch.sigma);
  EXPECT_NEAR(we.estimate.sigma, 1.0, 0.15);  // the weighted system's residual SD is about 1
  EXPECT_EQ(we.groups[1].base_count, 3);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    EXPECT_NEAR(we.groups[g].sigma, own_sigma(groups[g]), 1e-10 * own_sigma(groups[g]));
    EXPECT_FALSE(we.groups[g].weight_from_fallback);
  }
}

TEST(EquationGroups, ExactGroupTakesTheLargestWeightAndIsFlagged) {
  std::mt19937_64 rng(1);
  ls::EquationGroups eg(5, {"noisy", "exact", "empty"});
  const Group noisy = make_group(rng, 100, 5, 0.5);
  const Group exact = make_group(rng, 4, 5, 0.0);  // fewer rows than parameters: no sigma
  eg.fold(0, noisy.W, noisy.y);
  eg.fold(1, exact.W, exact.y);
  const ls::WeightedEstimate we = eg.estimate();
  EXPECT_FALSE(we.groups[0].weight_from_fallback);
  EXPECT_TRUE(we.groups[1].weight_from_fallback);
  EXPECT_EQ(we.groups[1].weight, we.groups[0].weight);
  EXPECT_EQ(we.groups[2].rows, 0u);
  EXPECT_EQ(we.groups[2].weight, 0.0);
  EXPECT_EQ(eg.index_of("exact"), 1u);
  EXPECT_THROW(eg.index_of("nope"), InputError);
}

}  // namespace
}  // namespace dynid::test
