// Fold throughput (rows/s) for n parameters and packet sizes, side by side in one run with
// the batch alternatives on the same rows:
//   - Fold/Extended: our accumulator, extended-precision Householder (the default);
//   - Fold/Double:   our accumulator, LAPACK dtpqrt in double;
//   - BatchDgeqrf:   dgeqrf of all rows at once + triangular solve (needs all rows in memory);
//   - NormalEquations: dsyrk/dgemv accumulation of W^T W per packet + Cholesky solve
//                    (fast, but squares the condition number);
//   - EigenHouseholder: Eigen's HouseholderQR of the stacked matrix.
// Every benchmark processes the same kTotalRows rows (whole packets), so items/s compare
// directly. Arguments: {n, packet} (batch ones ignore the packet).
#include <benchmark/benchmark.h>
#include <cblas.h>
#include <lapacke.h>

#include <Eigen/QR>
#include <random>

#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"

namespace {

constexpr Eigen::Index kTotalRows = 24000;

struct Rows {
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
};

const Rows& rows_for(Eigen::Index n) {
  static std::map<Eigen::Index, Rows> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  std::mt19937_64 rng(static_cast<unsigned>(n));
  std::normal_distribution<double> gauss;
  Rows r{Eigen::MatrixXd(kTotalRows, n), Eigen::VectorXd(kTotalRows)};
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < kTotalRows; ++i) r.W(i, j) = gauss(rng);
  for (Eigen::Index i = 0; i < kTotalRows; ++i) r.y(i) = gauss(rng);
  return cache.emplace(n, std::move(r)).first->second;
}

Eigen::Index whole_packets(Eigen::Index packet) {
  return (kTotalRows / packet) * packet;
}

void fold(benchmark::State& state, dynid::ls::Precision precision) {
  const Eigen::Index n = state.range(0), packet = state.range(1);
  const Rows& r = rows_for(n);
  const Eigen::Index total = whole_packets(packet);
  for (auto _ : state) {
    dynid::ls::Accumulator acc(n, precision);
    for (Eigen::Index first = 0; first < total; first += packet)
      acc.fold(r.W.middleRows(first, packet), r.y.segment(first, packet));
    benchmark::DoNotOptimize(dynid::ls::estimate(acc).value.data());
  }
  state.SetItemsProcessed(state.iterations() * total);
}

void BM_FoldExtended(benchmark::State& state) {
  fold(state, dynid::ls::Precision::kExtended);
}
void BM_FoldDouble(benchmark::State& state) {
  fold(state, dynid::ls::Precision::kDouble);
}

void BM_BatchDgeqrf(benchmark::State& state) {
  const Eigen::Index n = state.range(0);
  const Rows& r = rows_for(n);
  const auto m = static_cast<lapack_int>(kTotalRows), cols = static_cast<lapack_int>(n + 1);
  Eigen::MatrixXd a(kTotalRows, n + 1);
  Eigen::VectorXd tau(n + 1);
  for (auto _ : state) {
    a.leftCols(n) = r.W;  // dgeqrf overwrites its input: copying it is part of a batch solve
    a.col(n) = r.y;
    LAPACKE_dgeqrf(LAPACK_COL_MAJOR, m, cols, a.data(), m, tau.data());
    Eigen::VectorXd x =
        a.topLeftCorner(n, n).triangularView<Eigen::Upper>().solve(a.col(n).head(n));
    benchmark::DoNotOptimize(x.data());
  }
  state.SetItemsProcessed(state.iterations() * kTotalRows);
}

void BM_NormalEquations(benchmark::State& state) {
  const Eigen::Index n = state.range(0), packet = state.range(1);
  const Rows& r = rows_for(n);
  const Eigen::Index total = whole_packets(packet);
  const auto ni = static_cast<int>(n);
  for (auto _ : state) {
    Eigen::MatrixXd ata = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd aty = Eigen::VectorXd::Zero(n);
    for (Eigen::Index first = 0; first < total; first += packet) {
      const double* block = r.W.data() + first;  // column-major: rows first.. of every column
      const auto ld = static_cast<int>(kTotalRows);
      cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, ni, static_cast<int>(packet), 1.0, block,
                  ld, 1.0, ata.data(), ni);
      cblas_dgemv(CblasColMajor, CblasTrans, static_cast<int>(packet), ni, 1.0, block, ld,
                  r.y.data() + first, 1, 1.0, aty.data(), 1);
    }
    Eigen::VectorXd x = ata.selfadjointView<Eigen::Upper>().llt().solve(aty);
    benchmark::DoNotOptimize(x.data());
  }
  state.SetItemsProcessed(state.iterations() * total);
}

void BM_EigenHouseholder(benchmark::State& state) {
  const Eigen::Index n = state.range(0);
  const Rows& r = rows_for(n);
  for (auto _ : state) {
    Eigen::VectorXd x = r.W.householderQr().solve(r.y);
    benchmark::DoNotOptimize(x.data());
  }
  state.SetItemsProcessed(state.iterations() * kTotalRows);
}

void packet_grid(benchmark::internal::Benchmark* b) {
  for (long n : {4, 10, 16, 32, 64})
    for (long packet : {1, 16, 256, 3000}) b->Args({n, packet});
}
void batch_grid(benchmark::internal::Benchmark* b) {
  for (long n : {4, 10, 16, 32, 64}) b->Args({n, 0});
}

BENCHMARK(BM_FoldExtended)->Apply(packet_grid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FoldDouble)->Apply(packet_grid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NormalEquations)->Apply(packet_grid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BatchDgeqrf)->Apply(batch_grid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EigenHouseholder)->Apply(batch_grid)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
