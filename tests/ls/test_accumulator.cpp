// The accumulator against a batch LAPACK solve of all rows: random problems (n = 1..60),
// random packet sizes, random merge trees, forgetting, serialization.
#include <gtest/gtest.h>

#include <random>

#include "batch_reference.hpp"
#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"

namespace dynid::test {
namespace {

struct Problem {
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
};

// Well-conditioned random problem: Gaussian regressor, known x, noise of scale 0.1.
Problem random_problem(std::mt19937_64& rng, Eigen::Index n, Eigen::Index m) {
  std::normal_distribution<double> gauss;
  Problem p{Eigen::MatrixXd(m, n), Eigen::VectorXd(m)};
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = 0; j < n; ++j) p.W(i, j) = gauss(rng);
  Eigen::VectorXd x(n);
  for (Eigen::Index j = 0; j < n; ++j) x(j) = 10.0 * gauss(rng);
  p.y = p.W * x;
  for (Eigen::Index i = 0; i < m; ++i) p.y(i) += 0.1 * gauss(rng);
  return p;
}

// Cuts [0, m) into packets of random sizes between 1 and max_packet.
std::vector<std::pair<Eigen::Index, Eigen::Index>> random_packets(std::mt19937_64& rng,
                                                                  Eigen::Index m,
                                                                  Eigen::Index max_packet) {
  std::uniform_int_distribution<Eigen::Index> size(1, max_packet);
  std::vector<std::pair<Eigen::Index, Eigen::Index>> packets;
  for (Eigen::Index first = 0; first < m;) {
    const Eigen::Index count = std::min(size(rng), m - first);
    packets.push_back({first, count});
    first += count;
  }
  return packets;
}

// One accumulator per packet, then merged pairwise in a random order until one is left.
ls::Accumulator merge_tree(std::mt19937_64& rng, const Problem& p, Eigen::Index max_packet,
                           ls::Precision precision) {
  std::vector<ls::Accumulator> pool;
  for (auto [first, count] : random_packets(rng, p.W.rows(), max_packet)) {
    pool.emplace_back(p.W.cols(), precision);
    pool.back().fold(p.W.middleRows(first, count), p.y.segment(first, count));
  }
  while (pool.size() > 1) {
    std::uniform_int_distribution<std::size_t> pick(0, pool.size() - 1);
    const std::size_t a = pick(rng);
    std::size_t b = pick(rng);
    while (b == a) b = pick(rng);
    pool[a].merge(pool[b]);
    pool.erase(pool.begin() + static_cast<std::ptrdiff_t>(b));
  }
  return pool.front();
}

void expect_matches_batch(const ls::Accumulator& acc, const Problem& p, const std::string& what) {
  const BatchSolution batch = batch_solve(p.W, p.y);
  const ls::Estimate e = ls::estimate(acc);
  ASSERT_EQ(e.structure.rank(), p.W.cols()) << what;
  EXPECT_LT(relative_error(e.value, batch.x), 1e-12) << what;
  EXPECT_LT(relative_error(e.standard_deviation, batch.standard_deviation), 1e-12) << what;
  EXPECT_NEAR(e.residual_norm, batch.residual_norm, 1e-12 * batch.residual_norm) << what;
  EXPECT_NEAR(e.sigma, batch.sigma, 1e-12 * batch.sigma) << what;
  EXPECT_EQ(e.rows, static_cast<std::uint64_t>(p.W.rows())) << what;
}

// Both fold kernels (extended-precision Householder, LAPACK dtpqrt in double) must agree with
// the batch solve.
class BothPrecisions : public ::testing::TestWithParam<ls::Precision> {};

TEST_P(BothPrecisions, RandomPacketsEqualBatchSolve) {
  std::mt19937_64 rng(20261121);
  for (Eigen::Index n = 1; n <= 60; ++n) {
    const Eigen::Index m = 2 * n + 5 + static_cast<Eigen::Index>(rng() % 200);
    const Problem p = random_problem(rng, n, m);
    ls::Accumulator acc(n, GetParam());
    for (auto [first, count] : random_packets(rng, m, 1 + static_cast<Eigen::Index>(rng() % 64)))
      acc.fold(p.W.middleRows(first, count), p.y.segment(first, count));
    expect_matches_batch(acc, p, "n=" + std::to_string(n) + " sequential packets");
  }
}

TEST_P(BothPrecisions, RandomMergeTreesEqualBatchSolve) {
  std::mt19937_64 rng(42);
  for (Eigen::Index n = 1; n <= 60; n += 3) {
    const Eigen::Index m = 3 * n + 10 + static_cast<Eigen::Index>(rng() % 300);
    const Problem p = random_problem(rng, n, m);
    const ls::Accumulator acc =
        merge_tree(rng, p, 1 + static_cast<Eigen::Index>(rng() % 40), GetParam());
    expect_matches_batch(acc, p, "n=" + std::to_string(n) + " merge tree");
  }
}

TEST_P(BothPrecisions, LargeChunkIsFoldedInSlicesExactly) {
  std::mt19937_64 rng(7);
  const Problem p = random_problem(rng, 12, 10000);  // more rows than one internal slice
  ls::Accumulator acc(12, GetParam());
  acc.fold(p.W, p.y);
  expect_matches_batch(acc, p, "one 10000-row chunk");
}

INSTANTIATE_TEST_SUITE_P(Accumulator, BothPrecisions,
                         ::testing::Values(ls::Precision::kExtended, ls::Precision::kDouble),
                         [](const auto& param_info) {
                           return param_info.param == ls::Precision::kExtended ? "Extended"
                                                                               : "Double";
                         });

TEST(Accumulator, ForgettingEqualsExplicitRowWeights) {
  std::mt19937_64 rng(3);
  const Eigen::Index n = 6, packet = 20, packets = 8;
  const double lambda = 0.9;
  const Problem p = random_problem(rng, n, packet * packets);
  ls::Accumulator acc(n);
  Problem weighted = p;
  for (Eigen::Index k = 0; k < packets; ++k) {
    if (k > 0) acc.forget(lambda);
    acc.fold(p.W.middleRows(k * packet, packet), p.y.segment(k * packet, packet));
    // After the last packet, packet k has been forgotten (packets-1-k) times.
    const double w = std::sqrt(std::pow(lambda, static_cast<double>(packets - 1 - k)));
    weighted.W.middleRows(k * packet, packet) *= w;
    weighted.y.segment(k * packet, packet) *= w;
  }
  const BatchSolution batch = batch_solve(weighted.W, weighted.y);
  const ls::Estimate e = ls::estimate(acc);
  EXPECT_LT(relative_error(e.value, batch.x), 1e-12);
  EXPECT_NEAR(e.residual_norm, batch.residual_norm, 1e-12 * batch.residual_norm);
  double expected_rows = 0;
  for (Eigen::Index k = 0; k < packets; ++k)
    expected_rows += packet * std::pow(lambda, static_cast<double>(packets - 1 - k));
  EXPECT_NEAR(acc.effective_row_count(), expected_rows, 1e-12 * expected_rows);
}

TEST(Accumulator, ResidualAtAnyPointEqualsDirectResidual) {
  std::mt19937_64 rng(11);
  const Problem p = random_problem(rng, 8, 300);
  ls::Accumulator acc(8);
  acc.fold(p.W, p.y);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(8, -3.0, 4.0);
  const double direct = (p.W * x - p.y).norm();
  EXPECT_NEAR(acc.residual_norm_at(x), direct, 1e-12 * direct);
  EXPECT_NEAR(acc.measured_norm(), p.y.norm(), 1e-12 * p.y.norm());
}

TEST(Accumulator, SerializationRoundTripsBitForBit) {
  std::mt19937_64 rng(5);
  const Problem p = random_problem(rng, 10, 100);
  for (ls::Precision precision : {ls::Precision::kExtended, ls::Precision::kDouble}) {
    ls::Accumulator acc(10, precision);
    acc.fold(p.W, p.y);
    acc.forget(0.97);
    const std::string bytes = acc.serialize();
    const ls::Accumulator back = ls::Accumulator::deserialize(bytes);
    EXPECT_EQ(back.serialize(), bytes);
    EXPECT_EQ(back.row_count(), acc.row_count());
    EXPECT_EQ(back.effective_row_count(), acc.effective_row_count());
    EXPECT_TRUE((back.augmented_r().array() == acc.augmented_r().array()).all());
    // And it keeps folding where it left off.
    ls::Accumulator continued = back;
    continued.fold(p.W.topRows(5), p.y.head(5));
    acc.fold(p.W.topRows(5), p.y.head(5));
    EXPECT_EQ(continued.serialize(), acc.serialize());
    EXPECT_EQ(back.precision(), precision);
  }
}

}  // namespace
}  // namespace dynid::test
