#include "dynid/ingest/run_nuisance.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <string>

#include "dynid/error.hpp"

namespace dynid::ingest {

ls::EquationGroups eliminate_per_run(const ls::EquationGroups& run, const std::vector<Eigen::Index>& columns) {
  using ExtendedMatrix = ls::Accumulator::ExtendedMatrix;
  std::vector<std::string> names;
  for (std::size_t g = 0; g < run.size(); ++g) names.push_back(run.name(g));
  const Eigen::Index n = run.size() > 0 ? run.group(0).parameter_count() : 0;
  std::vector<Eigen::Index> sorted = columns;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < sorted.size(); ++i)
    if (sorted[i] < 0 || sorted[i] >= n || (i > 0 && sorted[i] == sorted[i - 1]))
      throw InputError("eliminate_per_run: column " + std::to_string(sorted[i]) + " is out of range [0, " +
                       std::to_string(n) + ") or repeated");
  ls::EquationGroups out(n, names);
  const auto k = static_cast<Eigen::Index>(sorted.size());
  // Column order: the nuisance columns first, then the others and y in their order.
  std::vector<Eigen::Index> order = sorted;
  for (Eigen::Index j = 0; j <= n; ++j)
    if (!std::binary_search(sorted.begin(), sorted.end(), j)) order.push_back(j);
  for (std::size_t g = 0; g < run.size(); ++g) {
    const ls::Accumulator& acc = run.group(g);
    if (acc.row_count() == 0) continue;
    if (acc.effective_row_count() != static_cast<double>(acc.row_count()))
      throw InputError("eliminate_per_run: group '" + run.name(g) + "' has forgetting; not supported");
    const ExtendedMatrix& r = acc.augmented_r_extended();
    ExtendedMatrix permuted(n + 1, n + 1);
    for (Eigen::Index j = 0; j <= n; ++j) permuted.col(j) = r.col(order[static_cast<std::size_t>(j)]);
    const Eigen::HouseholderQR<ExtendedMatrix> qr(permuted);
    const ExtendedMatrix t = qr.matrixQR().triangularView<Eigen::Upper>();
    // The rows below the nuisance block, put back in the original column order (nuisance
    // columns zero): the triangular factor of the projected rows.
    Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(n + 1 - k, n + 1);
    for (Eigen::Index j = k; j <= n; ++j)
      rows.col(order[static_cast<std::size_t>(j)]) = t.col(j).segment(k, n + 1 - k).cast<double>();
    ls::Accumulator& target = out.group(g);
    target.fold_augmented(rows);
    // The projected rows are r rows of rank r - k: the zero rows complete the row count so that
    // sigma's degrees of freedom are those of the batch problem (they change nothing else).
    const auto r_count = static_cast<Eigen::Index>(acc.row_count());
    const Eigen::Index missing = r_count - k - (n + 1 - k);
    if (missing > 0) target.fold_augmented(Eigen::MatrixXd::Zero(missing, n + 1));
  }
  return out;
}

}  // namespace dynid::ingest
