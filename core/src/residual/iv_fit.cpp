#include "dynid/residual/iv_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/QR>
#include <Eigen/SVD>
#include <boost/math/distributions/chi_squared.hpp>

#include "dynid/error.hpp"
#include "dynid/signal/butterworth.hpp"
#include "dynid/signal/derivative.hpp"
#include "dynid/signal/zero_phase_filter.hpp"
#include "folded_rows.hpp"
#include "hac_wald.hpp"

namespace dynid::residual {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Lags searched by instrument_lag, decimated rows: far beyond any Butterworth of order <= 8 at
// DYCARO's cut-off, whose impulse response dies out within a few decimated rows.
constexpr int kLongestLag = 64;
// Consecutive lags (and as many leads) taken as instruments from L on: see the header.
constexpr int kSpan = 3;

double autocorrelation(const Eigen::VectorXd& h, Eigen::Index lag) {
  const Eigen::Index n = h.size() - lag;
  return h.head(n).dot(h.tail(n)) / h.squaredNorm();
}

// The smallest lag (decimated rows) from which on |rho| <= bound up to kLongestLag.
int decorrelated_from(const Eigen::VectorXd& h, int odmf, double bound) {
  int lag = kLongestLag;
  while (lag > 1 && std::abs(autocorrelation(h, static_cast<Eigen::Index>(lag - 1) * odmf)) <= bound) --lag;
  return lag;
}

void validate(const IvOptions& o) {
  if (o.lag_rows < 0) throw InputError("iv_fit: lag_rows " + std::to_string(o.lag_rows) + " < 0");
  if (!(o.noise_correlation_bound > 0.0 && o.noise_correlation_bound < 1.0))
    throw InputError("iv_fit: noise_correlation_bound must be in (0, 1)");
  if (!(o.level > 0.0 && o.level < 1.0)) throw InputError("iv_fit: level must be in (0, 1)");
  if (!(o.min_instrument_f >= 0.0)) throw InputError("iv_fit: min_instrument_f must be >= 0");
}

// The weighted rows that have an instrument: W (identifiable columns only), Z (one block of W's
// columns per offset, zero where that partner is not a row), y, grid index.
struct Stacked {
  Eigen::MatrixXd w, z;
  Eigen::VectorXd y;
  std::vector<Eigen::Index> grid;
  std::uint64_t without_partner = 0;
};

// Index of the segment holding run grid index `grid`, or -1.
long segment_of(const std::vector<ingest::PreprocessedSegment>& run, Eigen::Index grid) {
  for (std::size_t s = 0; s < run.size(); ++s)
    if (grid >= run[s].first && grid < run[s].first + run[s].channels.samples()) return static_cast<long>(s);
  return -1;
}

// Row position of the group's row at `grid` in the same segment as `segment`, or -1.
long partner_of(const std::vector<Eigen::Index>& grids, Eigen::Index grid, long segment,
                const std::vector<ingest::PreprocessedSegment>& run) {
  const auto it = std::lower_bound(grids.begin(), grids.end(), grid);
  if (it == grids.end() || *it != grid || segment_of(run, grid) != segment) return -1;
  return static_cast<long>(it - grids.begin());
}

Stacked stack_rows(const detail::FoldedRows& rows, const std::vector<ingest::PreprocessedSegment>& run,
                   const std::vector<Eigen::Index>& used, const std::vector<double>& weights,
                   const std::vector<Eigen::Index>& offsets) {
  const auto width = static_cast<Eigen::Index>(rows.parameters.size());
  const auto k = static_cast<Eigen::Index>(used.size());
  std::vector<double> w, z, y;
  Stacked out;
  std::vector<long> partners(offsets.size());
  for (std::size_t g = 0; g < rows.collected.values.size(); ++g) {
    const std::vector<Eigen::Index>& grids = rows.collected.grid_index[g];
    const double* values = rows.collected.values[g].data();
    const auto at = [&](long i, Eigen::Index j) { return values[i * (width + 1) + j]; };
    for (std::size_t i = 0; i < grids.size(); ++i) {
      const long segment = segment_of(run, grids[i]);
      for (std::size_t o = 0; o < offsets.size(); ++o) partners[o] = partner_of(grids, grids[i] + offsets[o], segment, run);
      if (std::all_of(partners.begin(), partners.end(), [](long p) { return p < 0; })) {
        ++out.without_partner;
        continue;
      }
      for (Eigen::Index j : used) w.push_back(weights[g] * at(static_cast<long>(i), j));
      for (long p : partners)
        for (Eigen::Index j : used) z.push_back(p >= 0 ? weights[g] * at(p, j) : 0.0);
      y.push_back(weights[g] * at(static_cast<long>(i), width));
      out.grid.push_back(grids[i]);
    }
  }
  const auto n = static_cast<Eigen::Index>(y.size());
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  out.w = Eigen::Map<const RowMajor>(w.data(), n, k);
  out.z = Eigen::Map<const RowMajor>(z.data(), n, k * static_cast<Eigen::Index>(offsets.size()));
  out.y = Eigen::Map<const Eigen::VectorXd>(y.data(), n);
  return out;
}

// An orthonormal basis of the instruments' span, on unit-scaled columns (the offset column
// repeats in every block, and a block can be all zeros where its partner is never a row: the
// rank is the number of distinct instruments).
Eigen::MatrixXd instrument_basis(const Eigen::MatrixXd& z) {
  const Eigen::VectorXd norms = z.colwise().norm().transpose();
  Eigen::VectorXd scale = Eigen::VectorXd::Zero(norms.size());
  for (Eigen::Index j = 0; j < norms.size(); ++j)
    if (norms(j) > 0.0) scale(j) = 1.0 / norms(j);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(z * scale.asDiagonal());
  return qr.householderQ() * Eigen::MatrixXd::Identity(z.rows(), qr.rank());
}

// Weak-instrument check on unit-scaled columns: the smallest canonical correlation, its
// Cragg-Donald F, and the parameter the least well instrumented direction weighs most.
struct Instruments {
  double r_min = 0.0;
  double f = 0.0;
  Eigen::Index weakest = 0;  // column within `used`
};

Instruments instrument_strength(const Eigen::MatrixXd& qz, const Eigen::MatrixXd& ws) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(ws);
  const Eigen::MatrixXd qw = qr.householderQ() * Eigen::MatrixXd::Identity(ws.rows(), ws.cols());
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(qz.transpose() * qw, Eigen::ComputeFullV);
  Instruments out;
  const Eigen::Index k = ws.cols();
  out.r_min = qz.cols() < k ? 0.0 : std::min(1.0, svd.singularValues()(k - 1));
  const double n = static_cast<double>(ws.rows());
  const auto instruments = static_cast<double>(qz.cols());
  out.f = out.r_min >= 1.0 ? std::numeric_limits<double>::infinity()
                           : (n - instruments) / instruments * out.r_min * out.r_min / (1.0 - out.r_min * out.r_min);
  // The direction in parameter space: W a = Q_w v, a = R^-1 v.
  const Eigen::VectorXd a =
      qr.matrixQR().topRows(k).triangularView<Eigen::Upper>().solve(svd.matrixV().col(k - 1));
  a.cwiseAbs().maxCoeff(&out.weakest);
  return out;
}

std::string format(const char* pattern, double a, double b = 0.0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, pattern, a, b);
  return buf;
}

// HAC long-run covariance of row scores (rows x k) at the rows' grid indices.
Eigen::MatrixXd long_run(const Stacked& s, const Eigen::MatrixXd& scores, int odmf, int& bandwidth) {
  return detail::long_run_covariance(detail::sum_by_grid(s.grid, scores), odmf, bandwidth);
}

// The DWH statistic of d with covariance v: on unit diagonal, pseudo-inverse by SVD.
DurbinWuHausman hausman(const Eigen::VectorXd& d, const Eigen::MatrixXd& v, int bandwidth, double level) {
  DurbinWuHausman out;
  out.bandwidth = bandwidth;
  out.level = level;
  const Eigen::VectorXd c = v.diagonal().cwiseMax(std::numeric_limits<double>::min()).cwiseSqrt().cwiseInverse();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(c.asDiagonal() * v * c.asDiagonal(), Eigen::ComputeFullU);
  const Eigen::VectorXd projected = svd.matrixU().transpose() * c.asDiagonal() * d;
  const double largest = svd.singularValues()(0);
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (!(svd.singularValues()(i) > 1e-10 * largest)) break;
    out.statistic += projected(i) * projected(i) / svd.singularValues()(i);
    ++out.degrees_of_freedom;
  }
  if (out.degrees_of_freedom == 0) return out;
  out.p_value = boost::math::cdf(boost::math::complement(
      boost::math::chi_squared(static_cast<double>(out.degrees_of_freedom)), out.statistic));
  out.rejects = out.p_value < level;
  return out;
}

// Scatters the unit-scaled values of `used` columns back to the model's columns, NaN elsewhere.
Eigen::VectorXd unscaled(const Eigen::VectorXd& v, const Eigen::VectorXd& scale, const std::vector<Eigen::Index>& used,
                         Eigen::Index width) {
  Eigen::VectorXd out = Eigen::VectorXd::Constant(width, kNaN);
  for (std::size_t j = 0; j < used.size(); ++j) out(used[j]) = v(static_cast<Eigen::Index>(j)) * scale(static_cast<Eigen::Index>(j));
  return out;
}

// The estimates, their std and the test on the stacked rows (columns unit-scaled by `scale`).
// Two-stage least squares: the instrument of the formulas is W's projection on the instruments'
// span, zs = P_Z W (the first stage), so that theta_IV = (zs'W)^-1 zs'y.
void estimate(const Stacked& s, const Eigen::MatrixXd& qz, const Eigen::VectorXd& scale,
              const std::vector<Eigen::Index>& used, int odmf, const IvOptions& options, IvFit& fit) {
  const auto width = static_cast<Eigen::Index>(fit.parameters.size());
  const Eigen::MatrixXd ws = s.w * scale.asDiagonal();
  const Eigen::MatrixXd zs = qz * (qz.transpose() * ws);
  // zs'W = zs'zs: theta_IV is the least-squares solution of zs theta = y, solved by QR without
  // forming zs'W (whose condition number is the square of the columns').
  const Eigen::VectorXd iv = zs.colPivHouseholderQr().solve(s.y);
  const Eigen::VectorXd ls = ws.colPivHouseholderQr().solve(s.y);
  const Eigen::MatrixXd m_inverse = (zs.transpose() * ws).colPivHouseholderQr().inverse();
  const Eigen::MatrixXd g_inverse = (ws.transpose() * ws).ldlt().solve(Eigen::MatrixXd::Identity(ws.cols(), ws.cols()));
  const Eigen::VectorXd e_iv = s.y - ws * iv;
  const Eigen::VectorXd e_ls = s.y - ws * ls;
  const double s2 = e_iv.squaredNorm() / static_cast<double>(s.y.size() - ws.cols());
  const Eigen::MatrixXd textbook = s2 * m_inverse * (zs.transpose() * zs) * m_inverse.transpose();
  int bandwidth = 0;
  const Eigen::MatrixXd hac =
      m_inverse * long_run(s, zs.array().colwise() * e_iv.array(), odmf, bandwidth) * m_inverse.transpose();
  const Eigen::MatrixXd difference_scores =
      ((zs * m_inverse.transpose() - ws * g_inverse).array().colwise() * e_ls.array()).matrix();
  const Eigen::MatrixXd v_d = long_run(s, difference_scores, odmf, bandwidth);
  fit.residual_rms = std::sqrt(e_iv.squaredNorm() / static_cast<double>(s.y.size()));
  fit.ls_residual_rms = std::sqrt(e_ls.squaredNorm() / static_cast<double>(s.y.size()));
  fit.value = unscaled(iv, scale, used, width);
  fit.ls_value = unscaled(ls, scale, used, width);
  fit.std = unscaled(textbook.diagonal().cwiseMax(0.0).cwiseSqrt(), scale, used, width);
  fit.hac_std = unscaled(hac.diagonal().cwiseMax(0.0).cwiseSqrt(), scale, used, width);
  fit.difference_std = unscaled(v_d.diagonal().cwiseMax(0.0).cwiseSqrt(), scale, used, width);
  fit.dwh = hausman(iv - ls, v_d, bandwidth, options.level);
}

// The instruments' grid offsets: lags and leads L .. L + kSpan - 1 decimated rows.
std::vector<Eigen::Index> offsets(int lag_rows, int odmf) {
  std::vector<Eigen::Index> out;
  for (int l = lag_rows; l < lag_rows + kSpan; ++l) {
    out.push_back(-static_cast<Eigen::Index>(l) * odmf);
    out.push_back(static_cast<Eigen::Index>(l) * odmf);
  }
  return out;
}

// Refuses IV with `reason`: every value NaN.
void refuse(IvFit& fit, const std::string& reason) {
  fit.refused = true;
  fit.reason = reason;
  const auto width = static_cast<Eigen::Index>(fit.parameters.size());
  fit.value = fit.std = fit.hac_std = fit.ls_value = fit.difference_std = Eigen::VectorXd::Constant(width, kNaN);
}

// Unit column norms of W: the solves and the rank and strength checks then do not depend on the
// columns' units (a force beside an inertia).
Eigen::VectorXd column_scale(const Eigen::MatrixXd& w) {
  return w.colwise().norm().transpose().cwiseMax(std::numeric_limits<double>::min()).cwiseInverse();
}

// Why the rows cannot give an IV estimate, or empty.
std::string unusable(const Stacked& s, const Eigen::VectorXd& scale, const std::vector<Eigen::Index>& used,
                     const IvFit& fit, const IvOptions& options, const Instruments& strength) {
  const Eigen::Index k = s.w.cols();
  if (k == 0) return "the least-squares fit identifies no parameter";
  if (s.y.size() <= s.z.cols() + k) return "only " + std::to_string(s.y.size()) + " rows have an instrument";
  if ((s.w * scale.asDiagonal()).colPivHouseholderQr().rank() < k)
    return "the rows with an instrument do not identify every base parameter";
  if (!(strength.f >= options.min_instrument_f))
    return "weak instruments: the lagged rows (" + std::to_string(fit.lag_rows) +
           " decimated rows away) hardly carry the direction of '" +
           fit.parameters[static_cast<std::size_t>(used[static_cast<std::size_t>(strength.weakest)])].name +
           "' (smallest canonical correlation " + format("%.3g, Cragg-Donald F %.3g < ", strength.r_min, strength.f) +
           format("%g)", options.min_instrument_f);
  return {};
}

}  // namespace

std::string IvFit::statement() const {
  if (refused) return "instrumental variables refused (" + reason + "): the least-squares values are not tested for bias";
  char figures[160];
  std::snprintf(figures, sizeof figures, "Durbin-Wu-Hausman p = %.2g %s %g, %d dof", dwh.p_value,
                dwh.rejects ? "<" : ">=", dwh.level, dwh.degrees_of_freedom);
  if (dwh.rejects)
    return std::string("least squares is biased by noise in the regressors (") + figures +
           "): the instrumental-variable values are the estimate";
  return std::string("no evidence that noise in the regressors biases least squares (") + figures +
         "): the least-squares values stand";
}

int instrument_lag(const ingest::Preprocessing& preprocessing, double sample_rate_hz, double bound) {
  const signal::Sos sos = signal::butterworth_lowpass(preprocessing.butterworth_order,
                                                      preprocessing.cutoff(sample_rate_hz), sample_rate_hz);
  // A unit impulse far from both ends: the filter's response to it, and its derivative's, are the
  // shapes white noise takes through the preprocessing.
  const Eigen::Index half = static_cast<Eigen::Index>(2 * kLongestLag) * preprocessing.odmf;
  Eigen::VectorXd impulse = Eigen::VectorXd::Zero(2 * half + 1);
  impulse(half) = 1.0;
  const Eigen::VectorXd level = signal::zero_phase_filter(sos, impulse);
  const Eigen::VectorXd slope = signal::derivative(level, 1.0 / sample_rate_hz);
  return std::max(decorrelated_from(level, preprocessing.odmf, bound), decorrelated_from(slope, preprocessing.odmf, bound));
}

IvFit iv_fit(const model::Model& model, const std::vector<std::string>& effects,
             const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz, int odmf,
             const IvOptions& options) {
  validate(options);
  FitOptions fold_options = options.fit;
  fold_options.series = false;
  const detail::FoldedRows rows = detail::fold_rows(model, effects, run, sample_rate_hz, odmf, fold_options, true);
  const detail::Evaluation ls = detail::evaluate(rows, {}, {});
  IvFit fit;
  fit.model = model.name();
  fit.effects = effects;
  fit.parameters = rows.parameters;
  ingest::Preprocessing preprocessing = options.preprocessing;
  preprocessing.odmf = odmf;
  fit.lag_rows = options.lag_rows > 0 ? options.lag_rows
                                      : instrument_lag(preprocessing, sample_rate_hz, options.noise_correlation_bound);
  std::vector<Eigen::Index> used;  // the base parameters of the LS fit
  for (Eigen::Index j = 0; j < ls.all.value.size(); ++j)
    if (std::isfinite(ls.all.value(j))) used.push_back(j);
  const Stacked s = stack_rows(rows, run, used, ls.estimator_weights, offsets(fit.lag_rows, odmf));
  fit.rows = static_cast<std::uint64_t>(s.y.size());
  fit.rows_without_partner = s.without_partner;
  const Eigen::VectorXd scale = column_scale(s.w);
  Instruments strength;
  Eigen::MatrixXd qz;
  if (!used.empty() && s.y.size() > s.z.cols() + s.w.cols()) {
    qz = instrument_basis(s.z);
    strength = instrument_strength(qz, s.w * scale.asDiagonal());
    fit.smallest_canonical_correlation = strength.r_min;
    fit.instrument_f = strength.f;
  }
  if (const std::string reason = unusable(s, scale, used, fit, options, strength); !reason.empty()) {
    refuse(fit, reason);
    return fit;
  }
  estimate(s, qz, scale, used, odmf, options, fit);
  return fit;
}

}  // namespace dynid::residual
