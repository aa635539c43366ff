#pragma once
// Accumulator: the packet-wise (incremental) QR least-squares state of DYCARO
// (Venture 2003, §2.B.4; seeds/venture-2003.en.md §4.5).
//
// It holds the upper-triangular factor R_aug of the regressor W augmented with the measured side
// y as its last column:
//
//             [ R   z  ]      R (n x n) upper triangular, z = Q^T y (first n entries),
//   R_aug  =  [ 0  rho ]      |rho| = min_x ||W x - y|| when W has full column rank.
//
// R_aug^T R_aug = [W y]^T [W y] exactly (in exact arithmetic), so every least-squares quantity
// (estimate, residual norm, covariance, residual at any x, base parameters) follows from it
// without the raw rows. Memory is O(n^2) whatever the number of rows; folding m rows costs
// O(m n^2) with a structured Householder update of [R_aug; new rows].
//
// Precision. The state is kept in x87 extended precision (long double, 64-bit significand).
// Double precision is not enough for "exact": on ill-conditioned problems with a large residual
// the least-squares solution loses cond(W)^2 * eps * ||rho|| / (||W|| ||x||), which no
// backward-stable double algorithm avoids (batch LAPACK dgels reaches 5.8 digits on NIST
// Wampler5). Two fold kernels:
//  - Precision::kExtended (default): our structured Householder update in long double
//    (11 more bits: the NIST StRD certified values to >= 9 digits, Filip >= 7);
//  - Precision::kDouble: LAPACK's triangular-pentagonal QR (dtpqrt, blocked, OpenBLAS) in
//    double, for throughput when the data are far noisier than double rounding.
// Both agree with a batch double solve to rounding error on well-conditioned problems.
//
// Contract:
//  - fold, merge and scaling never lose accuracy with respect to a batch Householder QR of all
//    rows: the estimate agrees with a batch solve to rounding error;
//  - every mutator validates its input first and throws dynid::InputError (what, where, why)
//    leaving the accumulator unchanged;
//  - serialize()/deserialize() round-trip bit for bit, are versioned and checksummed.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::ls {

enum class Precision { kExtended, kDouble };

class Accumulator {
 public:
  using Extended = long double;
  using ExtendedMatrix = Eigen::Matrix<Extended, Eigen::Dynamic, Eigen::Dynamic>;

  /// An empty accumulator for `parameter_count` unknowns (1 <= n < 65536).
  explicit Accumulator(Eigen::Index parameter_count, Precision precision = Precision::kExtended);

  Eigen::Index parameter_count() const { return n_; }
  Precision precision() const { return precision_; }
  /// Rows folded in so far (merges add up; forgetting does not change it).
  std::uint64_t row_count() const { return rows_; }
  /// Sum of the row weights lambda^age: equals row_count() without forgetting. This is the
  /// row count that enters sigma^2 = ||rho||^2 / (r - n_B).
  double effective_row_count() const { return effective_rows_; }

  /// Folds the rows of W (m x n) with their measured side y (m): re-triangularizes [R_aug; W y].
  /// Throws InputError (accumulator unchanged) on a width or length mismatch or a NaN/Inf,
  /// naming the first offending row and column.
  void fold(const Eigen::Ref<const Eigen::MatrixXd>& W, const Eigen::Ref<const Eigen::VectorXd>& y);

  /// Folds rows given already augmented: each row is [w_1 .. w_n  y] (m x (n+1)).
  void fold_augmented(const Eigen::Ref<const Eigen::MatrixXd>& rows);

  /// Adds all rows of `other` (same parameter count): the result is the accumulator of the
  /// union of both row sets, whatever order they were folded in.
  void merge(const Accumulator& other);

  /// The accumulator of the same rows restricted to the regressor `columns` (strictly
  /// increasing, each < parameter_count(); y stays the measured side): R_aug of [W(:, columns) y]
  /// by re-triangularizing the selected columns of R_aug, which have the same Gram matrix.
  /// Row counts are kept. This is how the residual loop compares a model with and without a
  /// candidate effect on the same rows from one accumulator of [W | C | y]. InputError for an
  /// empty, unordered or out-of-range column list.
  Accumulator select_columns(const std::vector<Eigen::Index>& columns) const;

  /// Exponential forgetting: every row folded so far gets weight lambda (0 < lambda <= 1),
  /// i.e. R_aug *= sqrt(lambda) and the effective row count *= lambda.
  void forget(double lambda);

  /// Multiplies every row (regressor and measured side) by `weight` > 0: DYCARO's weighting
  /// of an equation group by 1/sigma_j. Row counts are unchanged.
  void scale_rows(double weight);

  /// R_aug, (n+1) x (n+1), upper triangular (the strictly lower part is zero), in the
  /// precision it is kept in, and rounded to double.
  const ExtendedMatrix& augmented_r_extended() const { return r_aug_; }
  Eigen::MatrixXd augmented_r() const { return r_aug_.cast<double>(); }
  /// ||y||: the norm of the measured side of all rows folded.
  double measured_norm() const;
  /// ||W x - y|| over all rows folded, for any x (from R_aug alone).
  double residual_norm_at(const Eigen::Ref<const Eigen::VectorXd>& x) const;

  /// Exact, versioned, checksummed binary state (little-endian; each entry of R_aug as the
  /// 10 bytes of an x87 extended value). The precision mode is part of the state.
  std::string serialize() const;
  /// Inverse of serialize(). Throws InputError naming the problem (truncated, bad magic,
  /// unsupported version, checksum mismatch, non-finite content).
  static Accumulator deserialize(std::string_view bytes);

 private:
  // Re-triangularizes [R_aug; B] where B (m x (n+1), column-major) holds new rows;
  // `triangular` says B is itself upper triangular (a merge), which halves the work.
  void fold_extended(Extended* rows, Eigen::Index m, bool triangular);
  void fold_double(double* rows, Eigen::Index m, bool triangular);
  void fold_slice(const Eigen::Ref<const Eigen::MatrixXd>& W,
                  const Eigen::Ref<const Eigen::VectorXd>& y);

  Eigen::Index n_;
  Precision precision_;
  std::uint64_t rows_ = 0;
  double effective_rows_ = 0.0;
  ExtendedMatrix r_aug_;
  // Workspace reused by fold() so steady-state folding allocates nothing.
  std::vector<Extended> pending_extended_;
  std::vector<double> pending_double_;
  std::vector<double> r_double_;
  std::vector<double> t_factor_;
  std::vector<double> work_;
};

}  // namespace dynid::ls
