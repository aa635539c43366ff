#include "dynid/ls/accumulator.hpp"

#include <lapacke.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "dynid/error.hpp"

namespace dynid::ls {
namespace {

using Extended = Accumulator::Extended;

static_assert(std::endian::native == std::endian::little,
              "the serialized state is little-endian; add byte swapping for this host");
static_assert(std::numeric_limits<Extended>::digits == 64,
              "the extended-precision state assumes x87 80-bit long double");

// Rows are folded in slices of at most this many, so the workspace stays bounded whatever
// the size of the chunk handed to fold().
constexpr Eigen::Index kSliceRows = 4096;
// dtpqrt block size: columns per compact-WY block. Small on purpose: dtpqrt2 builds the block's
// triangular factor T (extra O(m nb^2) work) that is only used on the trailing columns; with
// nb = n+1 that is pure overhead (measured: nb=4 is 1.3x faster than nb=n+1 at n=10, 1.6x at
// n=64; docs/BENCHMARKS.md).
constexpr Eigen::Index kMaxBlock = 4;

constexpr char kMagic[8] = {'D', 'Y', 'N', 'I', 'D', 'A', 'C', 'C'};
constexpr std::uint32_t kFormatVersion = 1;
constexpr std::uint32_t kMaxParameters = 1u << 16;
constexpr std::size_t kExtendedBytes = 10;  // significand (8) + sign and exponent (2)

std::string describe_value(double v) {
  return std::isnan(v) ? "NaN" : (v > 0 ? "+Inf" : "-Inf");
}

// Throws InputError for the first non-finite entry of `m`, naming its row and column.
void require_finite(const Eigen::Ref<const Eigen::MatrixXd>& m, const char* what) {
  if (m.allFinite()) return;
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      if (!std::isfinite(m(i, j)))
        throw InputError(std::string(what) + ": row " + std::to_string(i) + ", column " +
                         std::to_string(j) + " is " + describe_value(m(i, j)));
}

// The structured Householder update: re-triangularizes [R; B] in place, R (N x N upper
// triangular), B (m x N, column-major) the new rows, destroyed. Reflection k mixes row k of R
// with the m rows of B only, so the work is 2 m N^2 and R never grows. When B is upper
// triangular (a merge), column k of B is non-zero in its first k+1 rows only, and stays so.
// Dot products and updates go through Eigen, which vectorizes them for double.
template <typename Scalar>
void householder_fold(Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& R, Scalar* B,
                      Eigen::Index m, bool triangular) {
  using Column = Eigen::Map<Eigen::Matrix<Scalar, Eigen::Dynamic, 1>>;
  const Eigen::Index N = R.cols();
  for (Eigen::Index k = 0; k < N; ++k) {
    const Eigen::Index rows = triangular ? std::min(m, k + 1) : m;
    Column bk(B + k * m, rows);
    const Scalar tail = bk.squaredNorm();
    if (tail == 0) continue;  // nothing to annihilate in this column
    const Scalar alpha = R(k, k);
    // No overflow: entries come from doubles, and long double's range squares them safely.
    const Scalar norm = std::sqrt(alpha * alpha + tail);
    const Scalar beta = alpha >= 0 ? -norm : norm;
    const Scalar tau = (beta - alpha) / beta;
    bk /= (alpha - beta);  // v = [1; bk / (alpha - beta)]
    R(k, k) = beta;
    for (Eigen::Index j = k + 1; j < N; ++j) {
      Column bj(B + j * m, rows);
      const Scalar w = tau * (R(k, j) + bk.dot(bj));
      R(k, j) -= w;
      bj -= w * bk;
    }
  }
}

template <typename T>
void append_raw(std::string& out, const T& value, std::size_t bytes = sizeof(T)) {
  out.append(reinterpret_cast<const char*>(&value), bytes);
}

template <typename T>
T read_raw(std::string_view bytes, std::size_t& offset, std::size_t size = sizeof(T)) {
  T value{};
  std::memcpy(&value, bytes.data() + offset, size);
  offset += size;
  return value;
}

std::uint32_t crc32_of(std::string_view bytes) {
  return static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

std::size_t serialized_size(std::size_t n) {
  const std::size_t triangle = (n + 1) * (n + 2) / 2;
  return sizeof(kMagic) + 3 * sizeof(std::uint32_t) + sizeof(std::uint64_t) + sizeof(double) +
         triangle * kExtendedBytes + sizeof(std::uint32_t);
}

}  // namespace

Accumulator::Accumulator(Eigen::Index parameter_count, Precision precision)
    : n_(parameter_count), precision_(precision) {
  if (parameter_count < 1 || parameter_count >= static_cast<Eigen::Index>(kMaxParameters))
    throw InputError("accumulator: parameter count must be in [1, 65535], got " +
                     std::to_string(parameter_count));
  r_aug_ = ExtendedMatrix::Zero(n_ + 1, n_ + 1);
}

void Accumulator::fold(const Eigen::Ref<const Eigen::MatrixXd>& W,
                       const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (W.cols() != n_)
    throw InputError("fold: regressor has " + std::to_string(W.cols()) + " columns, expected " +
                     std::to_string(n_));
  if (y.size() != W.rows())
    throw InputError("fold: regressor has " + std::to_string(W.rows()) +
                     " rows but the measured side has " + std::to_string(y.size()));
  require_finite(W, "fold: regressor");
  require_finite(y, "fold: measured side");
  const Eigen::Index m = W.rows();
  for (Eigen::Index first = 0; first < m; first += kSliceRows) {
    const Eigen::Index count = std::min(kSliceRows, m - first);
    fold_slice(W.middleRows(first, count), y.segment(first, count));
  }
  rows_ += static_cast<std::uint64_t>(m);
  effective_rows_ += static_cast<double>(m);
}

void Accumulator::fold_slice(const Eigen::Ref<const Eigen::MatrixXd>& W,
                             const Eigen::Ref<const Eigen::VectorXd>& y) {
  const Eigen::Index m = W.rows();
  const auto size = static_cast<std::size_t>(m * (n_ + 1));
  if (precision_ == Precision::kExtended) {
    pending_extended_.resize(size);
    Eigen::Map<ExtendedMatrix> block(pending_extended_.data(), m, n_ + 1);
    block.leftCols(n_) = W.cast<Extended>();
    block.col(n_) = y.cast<Extended>();
    fold_extended(pending_extended_.data(), m, false);
  } else {
    pending_double_.resize(size);
    Eigen::Map<Eigen::MatrixXd> block(pending_double_.data(), m, n_ + 1);
    block.leftCols(n_) = W;
    block.col(n_) = y;
    fold_double(pending_double_.data(), m, false);
  }
}

void Accumulator::fold_augmented(const Eigen::Ref<const Eigen::MatrixXd>& rows) {
  if (rows.cols() != n_ + 1)
    throw InputError("fold: augmented rows have " + std::to_string(rows.cols()) +
                     " columns, expected " + std::to_string(n_ + 1) + " (n parameters + measured)");
  fold(rows.leftCols(n_), rows.col(n_));
}

void Accumulator::merge(const Accumulator& other) {
  if (other.n_ != n_)
    throw InputError("merge: accumulators have " + std::to_string(other.n_) + " and " +
                     std::to_string(n_) + " parameters");
  const Eigen::Index order = n_ + 1;
  const auto size = static_cast<std::size_t>(order * order);
  if (precision_ == Precision::kExtended) {
    pending_extended_.resize(size);
    Eigen::Map<ExtendedMatrix>(pending_extended_.data(), order, order) = other.r_aug_;
    fold_extended(pending_extended_.data(), order, true);
  } else {
    pending_double_.resize(size);
    Eigen::Map<Eigen::MatrixXd>(pending_double_.data(), order, order) = other.r_aug_.cast<double>();
    fold_double(pending_double_.data(), order, true);
  }
  rows_ += other.rows_;
  effective_rows_ += other.effective_rows_;
}

Accumulator Accumulator::select_columns(const std::vector<Eigen::Index>& columns) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] < 0 || columns[i] >= n_ || (i > 0 && columns[i] <= columns[i - 1]))
      throw InputError("select_columns: column list must be increasing within 0.." +
                       std::to_string(n_ - 1) + " (entry " + std::to_string(i) + " is " +
                       std::to_string(columns[i]) + ")");
  if (columns.empty()) throw InputError("select_columns: no column selected");
  Accumulator out(static_cast<Eigen::Index>(columns.size()), precision_);
  const Eigen::Index order = out.n_ + 1;
  const Eigen::Index m = n_ + 1;  // rows of R_aug
  ExtendedMatrix selected(m, order);
  for (Eigen::Index j = 0; j < out.n_; ++j) selected.col(j) = r_aug_.col(columns[static_cast<std::size_t>(j)]);
  selected.col(out.n_) = r_aug_.col(n_);
  if (precision_ == Precision::kExtended) {
    out.fold_extended(selected.data(), m, false);
  } else {
    Eigen::MatrixXd rows = selected.cast<double>();
    out.fold_double(rows.data(), m, false);
  }
  out.rows_ = rows_;
  out.effective_rows_ = effective_rows_;
  return out;
}

void Accumulator::fold_extended(Extended* rows, Eigen::Index m, bool triangular) {
  householder_fold<Extended>(r_aug_, rows, m, triangular);
}

void Accumulator::fold_double(double* rows, Eigen::Index m, bool triangular) {
  const Eigen::Index order = n_ + 1;
  const Eigen::Index block = std::min(order, kMaxBlock);
  r_double_.resize(static_cast<std::size_t>(order * order));
  t_factor_.resize(static_cast<std::size_t>(block * order));
  work_.resize(static_cast<std::size_t>(block * order));
  Eigen::Map<Eigen::MatrixXd> r(r_double_.data(), order, order);
  r = r_aug_.cast<double>();
  const auto as_int = [](Eigen::Index v) { return static_cast<lapack_int>(v); };
  // l = order: B is upper trapezoidal (a merge); l = 0: B is a plain rectangle of rows.
  const lapack_int info = LAPACKE_dtpqrt_work(
      LAPACK_COL_MAJOR, as_int(m), as_int(order), triangular ? as_int(order) : 0, as_int(block),
      r.data(), as_int(order), rows, as_int(m), t_factor_.data(), as_int(block), work_.data());
  if (info != 0)  // Only argument errors can fail; they are programming errors here.
    throw std::logic_error("dtpqrt failed with info " + std::to_string(info));
  r.triangularView<Eigen::StrictlyLower>().setZero();
  r_aug_ = r.cast<Extended>();
}

void Accumulator::forget(double lambda) {
  if (!(lambda > 0.0 && lambda <= 1.0))
    throw InputError("forget: lambda must be in (0, 1], got " + std::to_string(lambda));
  r_aug_ *= std::sqrt(static_cast<Extended>(lambda));
  effective_rows_ *= lambda;
}

void Accumulator::scale_rows(double weight) {
  if (!(weight > 0.0 && std::isfinite(weight)))
    throw InputError("scale_rows: weight must be finite and > 0, got " + std::to_string(weight));
  r_aug_ *= static_cast<Extended>(weight);
}

double Accumulator::measured_norm() const {
  return static_cast<double>(r_aug_.col(n_).norm());
}

double Accumulator::residual_norm_at(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  if (x.size() != n_)
    throw InputError("residual_norm_at: x has " + std::to_string(x.size()) + " entries, expected " +
                     std::to_string(n_));
  Eigen::Matrix<Extended, Eigen::Dynamic, 1> extended(n_ + 1);
  extended << x.cast<Extended>(), -1.0L;
  return static_cast<double>((r_aug_.triangularView<Eigen::Upper>() * extended).norm());
}

std::string Accumulator::serialize() const {
  std::string out;
  out.reserve(serialized_size(static_cast<std::size_t>(n_)));
  out.append(kMagic, sizeof(kMagic));
  append_raw(out, kFormatVersion);
  append_raw(out, static_cast<std::uint32_t>(n_));
  append_raw(out, static_cast<std::uint32_t>(precision_ == Precision::kExtended ? 0 : 1));
  append_raw(out, rows_);
  append_raw(out, effective_rows_);
  for (Eigen::Index j = 0; j <= n_; ++j)
    for (Eigen::Index i = 0; i <= j; ++i) append_raw(out, r_aug_(i, j), kExtendedBytes);
  append_raw(out, crc32_of(out));
  return out;
}

Accumulator Accumulator::deserialize(std::string_view bytes) {
  const std::size_t header = sizeof(kMagic) + 2 * sizeof(std::uint32_t);
  if (bytes.size() < header)
    throw InputError("accumulator state: truncated: " + std::to_string(bytes.size()) +
                     " bytes, shorter than the " + std::to_string(header) + "-byte header");
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    throw InputError("accumulator state: bad magic (not a dynid accumulator)");
  std::size_t offset = sizeof(kMagic);
  const auto version = read_raw<std::uint32_t>(bytes, offset);
  if (version != kFormatVersion)
    throw InputError("accumulator state: unsupported format version " + std::to_string(version) +
                     " (this build reads version " + std::to_string(kFormatVersion) + ")");
  const auto n = read_raw<std::uint32_t>(bytes, offset);
  if (n < 1 || n >= kMaxParameters)
    throw InputError("accumulator state: parameter count " + std::to_string(n) + " out of range");
  const std::size_t expected = serialized_size(n);
  if (bytes.size() != expected)
    throw InputError("accumulator state: " + std::to_string(bytes.size()) + " bytes, expected " +
                     std::to_string(expected) + " for " + std::to_string(n) + " parameters" +
                     (bytes.size() < expected ? " (truncated)" : " (trailing bytes)"));
  std::size_t crc_offset = expected - sizeof(std::uint32_t);
  const auto stored_crc = read_raw<std::uint32_t>(bytes, crc_offset);
  if (stored_crc != crc32_of(bytes.substr(0, expected - sizeof(std::uint32_t))))
    throw InputError("accumulator state: checksum mismatch (corrupted)");
  const auto precision = read_raw<std::uint32_t>(bytes, offset);
  if (precision > 1)
    throw InputError("accumulator state: unknown precision mode " + std::to_string(precision));

  Accumulator acc(static_cast<Eigen::Index>(n),
                  precision == 0 ? Precision::kExtended : Precision::kDouble);
  acc.rows_ = read_raw<std::uint64_t>(bytes, offset);
  acc.effective_rows_ = read_raw<double>(bytes, offset);
  if (!(std::isfinite(acc.effective_rows_) && acc.effective_rows_ >= 0.0))
    throw InputError("accumulator state: effective row count is not a finite value >= 0");
  for (Eigen::Index j = 0; j <= acc.n_; ++j)
    for (Eigen::Index i = 0; i <= j; ++i) {
      acc.r_aug_(i, j) = read_raw<Extended>(bytes, offset, kExtendedBytes);
      if (!std::isfinite(acc.r_aug_(i, j)))
        throw InputError("accumulator state: R(" + std::to_string(i) + ", " + std::to_string(j) +
                         ") is not finite");
    }
  return acc;
}

}  // namespace dynid::ls
