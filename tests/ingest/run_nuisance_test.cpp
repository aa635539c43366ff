// eliminate_per_run: runs pooled after their per-run columns are eliminated give the estimate of
// one batch solve with one such column per run (values, standard deviations, sigma).
#include "dynid/ingest/run_nuisance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dynid/error.hpp"

namespace dynid::ingest {
namespace {

constexpr double kA = 2.5, kB = -0.7;

// Rows [x1, x2, -1] of a run whose offset is `offset`: y = a x1 + b x2 - offset + noise.
void make_rows(unsigned seed, double offset, Eigen::Index m, Eigen::MatrixXd& W, Eigen::VectorXd& y) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  W.resize(m, 3);
  y.resize(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    W(k, 0) = 3.0 + n(rng);
    W(k, 1) = std::sin(0.01 * static_cast<double>(k)) * 5.0 + n(rng);
    W(k, 2) = -1.0;
    y(k) = kA * W(k, 0) + kB * W(k, 1) - offset + 0.1 * n(rng);
  }
}

TEST(EliminatePerRun, PooledRunsEqualOneBatchSolveWithAnOffsetPerRun) {
  const std::vector<double> offsets{3.0, -4.0, 0.5};
  const std::vector<Eigen::Index> sizes{400, 250, 900};
  ls::EquationGroups pooled(3, {"engine"});
  ls::EquationGroups shared(3, {"engine"});
  Eigen::Index total = 0;
  for (Eigen::Index m : sizes) total += m;
  Eigen::MatrixXd batch = Eigen::MatrixXd::Zero(total, 2 + static_cast<Eigen::Index>(offsets.size()));
  Eigen::VectorXd batch_y(total);
  Eigen::Index at = 0;
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    Eigen::MatrixXd W;
    Eigen::VectorXd y;
    make_rows(static_cast<unsigned>(i + 1), offsets[i], sizes[i], W, y);
    ls::EquationGroups run(3, {"engine"});
    run.fold(0, W, y);
    shared.group(0).merge(run.group(0));
    const ls::EquationGroups reduced = eliminate_per_run(run, {2});
    EXPECT_EQ(reduced.group(0).row_count(), run.group(0).row_count() - 1);
    pooled.group(0).merge(reduced.group(0));
    batch.block(at, 0, sizes[i], 2) = W.leftCols(2);
    batch.col(2 + static_cast<Eigen::Index>(i)).segment(at, sizes[i]).setConstant(-1.0);
    batch_y.segment(at, sizes[i]) = y;
    at += sizes[i];
  }
  ls::EquationGroups reference(batch.cols(), {"engine"});
  reference.fold(0, batch, batch_y);
  const ls::Estimate p = pooled.estimate().estimate;
  const ls::Estimate b = reference.estimate().estimate;
  for (Eigen::Index j = 0; j < 2; ++j) {
    EXPECT_NEAR(p.value(j), b.value(j), 1e-12 * std::abs(b.value(j))) << j;
    EXPECT_NEAR(p.standard_deviation(j), b.standard_deviation(j), 1e-9 * b.standard_deviation(j)) << j;
  }
  EXPECT_NEAR(p.sigma, b.sigma, 1e-9 * b.sigma);
  EXPECT_EQ(p.structure.status[2], ls::ParameterStatus::kEliminated);
  EXPECT_TRUE(std::isnan(p.value(2)));
  EXPECT_NEAR(b.value(0), kA, 0.01);
  // One shared offset column fits their mean to rows with different offsets: biased.
  const ls::Estimate s = shared.estimate().estimate;
  EXPECT_GT(std::abs(s.value(0) - kA), 50.0 * std::abs(p.value(0) - kA));
}

TEST(EliminatePerRun, RejectsBadColumnsAndKeepsEmptyGroupsEmpty) {
  ls::EquationGroups run(3, {"a", "b"});
  run.fold(0, Eigen::MatrixXd::Ones(4, 3), Eigen::VectorXd::Ones(4));
  EXPECT_THROW((void)eliminate_per_run(run, {3}), InputError);
  EXPECT_THROW((void)eliminate_per_run(run, {1, 1}), InputError);
  EXPECT_THROW((void)eliminate_per_run(run, {-1}), InputError);
  const ls::EquationGroups reduced = eliminate_per_run(run, {0});
  EXPECT_EQ(reduced.group(1).row_count(), 0u);
  EXPECT_EQ(reduced.name(1), "b");
}

}  // namespace
}  // namespace dynid::ingest
