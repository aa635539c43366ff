// Rank deficiency: eliminated (zero) columns, dependent columns regrouped into earlier ones,
// and the regrouping relation X_B = X_s1 + beta X_s2 reproducing the same fitted values.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <random>

#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"

namespace dynid::test {
namespace {

using ls::ParameterStatus;

struct Deficient {
  Eigen::MatrixXd W;
  Eigen::VectorXd x_true;
};

// Columns: 0, 1 random; 2 zero; 3 = 2*c0 - c1; 4 random; 5 = c4.
Deficient deficient_problem(Eigen::Index m) {
  std::mt19937_64 rng(99);
  std::normal_distribution<double> gauss;
  Deficient d{Eigen::MatrixXd::Zero(m, 6), Eigen::VectorXd(6)};
  for (Eigen::Index i = 0; i < m; ++i) {
    d.W(i, 0) = gauss(rng);
    d.W(i, 1) = gauss(rng);
    d.W(i, 4) = gauss(rng);
  }
  d.W.col(3) = 2.0 * d.W.col(0) - d.W.col(1);
  d.W.col(5) = d.W.col(4);
  d.x_true << 1.5, -2.0, 7.0, 0.25, 3.0, -1.0;
  return d;
}

ls::Estimate fold_in_packets(const Eigen::MatrixXd& W, const Eigen::VectorXd& y) {
  ls::Accumulator acc(W.cols());
  for (Eigen::Index first = 0; first < W.rows(); first += 17) {
    const Eigen::Index count = std::min<Eigen::Index>(17, W.rows() - first);
    acc.fold(W.middleRows(first, count), y.segment(first, count));
  }
  return ls::estimate(acc);
}

Eigen::VectorXd base_values_of(const ls::Estimate& e) {
  Eigen::VectorXd v(e.structure.rank());
  for (Eigen::Index k = 0; k < v.size(); ++k)
    v(k) = e.value(e.structure.base[static_cast<std::size_t>(k)]);
  return v;
}

Eigen::MatrixXd base_columns(const Eigen::MatrixXd& W, const ls::Estimate& e) {
  Eigen::MatrixXd out(W.rows(), e.structure.rank());
  for (Eigen::Index k = 0; k < out.cols(); ++k)
    out.col(k) = W.col(e.structure.base[static_cast<std::size_t>(k)]);
  return out;
}

TEST(BaseParameters, ClassifiesZeroAndDependentColumns) {
  const Deficient d = deficient_problem(400);
  const ls::Estimate e = fold_in_packets(d.W, d.W * d.x_true);
  EXPECT_EQ(e.structure.rank(), 3);
  EXPECT_EQ(e.structure.base, (std::vector<Eigen::Index>{0, 1, 4}));
  EXPECT_EQ(e.structure.dependent, (std::vector<Eigen::Index>{3, 5}));
  EXPECT_EQ(e.structure.eliminated, (std::vector<Eigen::Index>{2}));
  const std::vector<ParameterStatus> expected{
      ParameterStatus::kRegrouped, ParameterStatus::kRegrouped, ParameterStatus::kEliminated,
      ParameterStatus::kDependent, ParameterStatus::kRegrouped, ParameterStatus::kDependent};
  EXPECT_EQ(e.structure.status, expected);
  Eigen::MatrixXd beta_expected(3, 2);
  beta_expected << 2, 0, -1, 0, 0, 1;
  EXPECT_LT((e.structure.regrouping - beta_expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_TRUE(std::isnan(e.value(2)) && std::isnan(e.value(3)) && std::isnan(e.value(5)));
  const std::vector<std::string> names{"a", "b", "c", "d", "e", "f"};
  EXPECT_EQ(e.structure.relation(0, names), "a + 2*d");
  EXPECT_EQ(e.structure.relation(1, names), "b - d");
  EXPECT_EQ(e.structure.relation(2, names), "e + f");
}

// Full rank: the regrouping matrix has no column (and no storage), every parameter is
// identified. Taking rows of that empty matrix was pointer arithmetic on null (clang's UBSan,
// tests/fuzz/fuzz_chunk); this case runs that path in every sanitizer build.
TEST(BaseParameters, FullRankHasNoRegrouping) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  Eigen::MatrixXd W(50, 3);
  for (Eigen::Index i = 0; i < W.size(); ++i) W.data()[i] = gauss(rng);
  const ls::Estimate e = fold_in_packets(W, W * Eigen::Vector3d(1.0, -2.0, 0.5));
  EXPECT_EQ(e.structure.rank(), 3);
  EXPECT_EQ(e.structure.regrouping.rows(), 3);
  EXPECT_EQ(e.structure.regrouping.cols(), 0);
  EXPECT_EQ(e.structure.status, std::vector<ParameterStatus>(3, ParameterStatus::kIdentified));
}

TEST(BaseParameters, NoiseFreeEstimateEqualsRegroupedTruth) {
  const Deficient d = deficient_problem(400);
  const ls::Estimate e = fold_in_packets(d.W, d.W * d.x_true);
  const Eigen::VectorXd expected = e.structure.base_values(d.x_true);  // X_s1 + beta X_s2
  EXPECT_LT((base_values_of(e) - expected).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_NEAR(expected(0), 1.5 + 2 * 0.25, 1e-12);  // a + 2 d, by hand
}

TEST(BaseParameters, RegroupedModelReproducesFittedValues) {
  const Deficient d = deficient_problem(400);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> gauss(0.0, 0.3);
  Eigen::VectorXd y = d.W * d.x_true;
  for (Eigen::Index i = 0; i < y.size(); ++i) y(i) += gauss(rng);
  const ls::Estimate e = fold_in_packets(d.W, y);
  // Reference: minimum-norm batch solution of the full, rank-deficient W.
  const Eigen::VectorXd x_min_norm = d.W.completeOrthogonalDecomposition().solve(y);
  const Eigen::VectorXd fitted_reference = d.W * x_min_norm;
  const Eigen::VectorXd fitted = base_columns(d.W, e) * base_values_of(e);
  EXPECT_LT((fitted - fitted_reference).cwiseAbs().maxCoeff(), 1e-10 * fitted_reference.norm());
  EXPECT_NEAR(e.residual_norm, (y - fitted_reference).norm(), 1e-10 * y.norm());
  EXPECT_NEAR(e.degrees_of_freedom, 400.0 - 3.0, 0.0);
}

TEST(BaseParameters, ZeroToleranceEliminatesNegligibleColumns) {
  Deficient d = deficient_problem(200);
  d.W.col(2).setConstant(1e-9);  // excited, but negligibly against the others
  const Eigen::VectorXd y = d.W * d.x_true;
  ls::Accumulator acc(6);
  acc.fold(d.W, y);
  ls::EstimateOptions strict;
  EXPECT_EQ(ls::estimate(acc, strict).structure.status[2], ParameterStatus::kIdentified);
  ls::EstimateOptions tolerant;
  tolerant.base.zero_tolerance = 1e-6;
  EXPECT_EQ(ls::estimate(acc, tolerant).structure.status[2], ParameterStatus::kEliminated);
}

TEST(BaseParameters, ScaleOfUnitsDoesNotChangeTheStructure) {
  // Same problem with one parameter in "grams": the column shrinks by 1e3; the structure and
  // the (rescaled) estimate must not change.
  const Deficient d = deficient_problem(300);
  Eigen::MatrixXd W = d.W;
  W.col(4) *= 1e-3;
  W.col(5) *= 1e-3;
  const ls::Estimate e = fold_in_packets(W, d.W * d.x_true);
  EXPECT_EQ(e.structure.base, (std::vector<Eigen::Index>{0, 1, 4}));
  EXPECT_NEAR(e.value(4), 1e3 * (3.0 - 1.0), 1e-8);
}

}  // namespace
}  // namespace dynid::test
