// Peak resident memory of folding N rows in packets of 256 with n = 10 parameters, the rows
// generated on the fly (as they arrive from a stream). Usage: bench_fold_memory ROWS
// Prints the peak RSS (KiB) and the estimate's first value. Memory must not grow with ROWS.
#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <random>

#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s ROWS\n", argv[0]);
    return 2;
  }
  const long long total = std::atoll(argv[1]);
  constexpr Eigen::Index kN = 10, kPacket = 256;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> gauss;
  dynid::ls::Accumulator acc(kN);
  Eigen::MatrixXd W(kPacket, kN);
  Eigen::VectorXd y(kPacket);
  for (long long done = 0; done < total; done += kPacket) {
    const Eigen::Index m = static_cast<Eigen::Index>(std::min<long long>(kPacket, total - done));
    for (Eigen::Index i = 0; i < m; ++i) {
      for (Eigen::Index j = 0; j < kN; ++j) W(i, j) = gauss(rng);
      y(i) = W.row(i).sum() + 0.1 * gauss(rng);
    }
    acc.fold(W.topRows(m), y.head(m));
  }
  const auto e = dynid::ls::estimate(acc);
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("rows %lld  peak_rss_kib %ld  x0 %.6f\n", total, usage.ru_maxrss, e.value(0));
  return 0;
}
