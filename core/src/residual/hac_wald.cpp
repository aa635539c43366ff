#include "hac_wald.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/Eigenvalues>
#include <boost/math/distributions/chi_squared.hpp>

namespace dynid::residual::detail {
namespace {

// Each row's weighted score u' e, in group order, with its grid index; `information` = sum u u'.
TimeScores scores_by_time(const FoldedRows& rows, const Eigen::VectorXd& x, const std::vector<double>& weights,
                          const std::vector<Eigen::Index>& used, Eigen::MatrixXd& information) {
  const auto width = static_cast<Eigen::Index>(rows.parameters.size());
  const auto k = static_cast<Eigen::Index>(used.size());
  information = Eigen::MatrixXd::Zero(k, k);
  std::vector<Eigen::Index> grid;
  std::vector<Eigen::VectorXd> scores;
  for (std::size_t g = 0; g < rows.collected.values.size(); ++g) {
    const std::vector<double>& v = rows.collected.values[g];
    const Eigen::Index m = static_cast<Eigen::Index>(v.size()) / (width + 1);
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> all(
        v.data(), m, width + 1);
    const double w = weights[g];
    for (Eigen::Index i = 0; i < m; ++i) {
      Eigen::VectorXd u(k);
      double fitted = 0.0;
      for (Eigen::Index j = 0; j < k; ++j) {
        u(j) = w * all(i, used[static_cast<std::size_t>(j)]);
        fitted += all(i, used[static_cast<std::size_t>(j)]) * x(used[static_cast<std::size_t>(j)]);
      }
      const double e = w * (all(i, width) - fitted);
      information.noalias() += u * u.transpose();
      grid.push_back(rows.collected.grid_index[g][static_cast<std::size_t>(i)]);
      scores.push_back(u * e);
    }
  }
  Eigen::MatrixXd stacked(static_cast<Eigen::Index>(scores.size()), k);
  for (std::size_t i = 0; i < scores.size(); ++i) stacked.row(static_cast<Eigen::Index>(i)) = scores[i].transpose();
  return sum_by_grid(grid, stacked);
}

// Divides each score component by its root mean square (1 where it is 0) and returns those
// scales. Why: the covariance must not depend on the parameters' units. Andrews' bandwidth weighs
// the components by their variances, and a column in kN rather than N would otherwise move it;
// on unit-scaled scores the whole estimate is equivariant, S = D S_unit D.
Eigen::VectorXd to_unit_scale(TimeScores& t) {
  const Eigen::Index k = t.score.empty() ? 0 : t.score.front().size();
  Eigen::VectorXd rms = Eigen::VectorXd::Zero(k);
  for (const Eigen::VectorXd& s : t.score) rms += s.cwiseAbs2();
  if (!t.score.empty()) rms = (rms / static_cast<double>(t.score.size())).cwiseSqrt();
  for (Eigen::Index a = 0; a < k; ++a)
    if (!(rms(a) > 0.0)) rms(a) = 1.0;
  for (Eigen::VectorXd& s : t.score) s = s.cwiseQuotient(rms);
  return rms;
}

// Andrews and Monahan (1992): the scores are prewhitened by a VAR(1) fitted over pairs of rows
// one decimation step apart, s_t = A s_{t-1} + v_t, the HAC estimate is taken of v and recoloured,
// S = (I - A)^-1 S_v (I - A)^-T. Why: low-passed rows make the scores strongly autocorrelated,
// and a kernel estimate alone then understates their long-run variance on a run of a few hundred
// rows (the test over-rejects, the stds are short); prewhitening leaves the kernel little to do.
// A is shrunk to a spectral radius of 0.97 at most (their bound), so that the VAR is stationary
// and (I - A) invertible. The radius, not the spectral norm: the scores of correlated columns
// give a non-normal A whose norm is several times its radius (measured: 2.5 against 0.1 on the
// clutch model's unit-scaled scores), and bounding the norm shrank such an A to nearly nothing,
// which is no prewhitening at all.
Eigen::MatrixXd prewhiten(TimeScores& t, int odmf) {
  const Eigen::Index k = t.score.empty() ? 0 : t.score.front().size();
  Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(k, k);
  Eigen::MatrixXd lagged = Eigen::MatrixXd::Zero(k, k);
  for (std::size_t i = 1; i < t.score.size(); ++i)
    if (t.grid[i] - t.grid[i - 1] == odmf) {
      cross.noalias() += t.score[i] * t.score[i - 1].transpose();
      lagged.noalias() += t.score[i - 1] * t.score[i - 1].transpose();
    }
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(k, k);
  if (lagged.trace() > 0.0)
    a = lagged.transpose().completeOrthogonalDecomposition().solve(cross.transpose()).transpose();
  const double radius = a.size() > 0 ? a.eigenvalues().cwiseAbs().maxCoeff() : 0.0;
  if (radius > 0.97) a *= 0.97 / radius;
  for (std::size_t i = t.score.size(); i-- > 1;)
    if (t.grid[i] - t.grid[i - 1] == odmf) t.score[i] -= a * t.score[i - 1];
  return a;
}

// Andrews (1991), Bartlett kernel, AR(1) plug-in per score component a (rho_a, innovation
// variance s_a): alpha = sum 4 rho^2 s^4 / ((1 - rho)^6 (1 + rho)^2) / sum s^4 / (1 - rho)^4,
// L = 1.1447 (alpha n)^(1/3).
int andrews_bandwidth(const TimeScores& t, int odmf) {
  const Eigen::Index k = t.score.empty() ? 0 : t.score.front().size();
  double numerator = 0.0;
  double denominator = 0.0;
  for (Eigen::Index a = 0; a < k; ++a) {
    double xy = 0.0, xx = 0.0;
    for (std::size_t i = 1; i < t.score.size(); ++i)
      if (t.grid[i] - t.grid[i - 1] == odmf) {
        xy += t.score[i](a) * t.score[i - 1](a);
        xx += t.score[i - 1](a) * t.score[i - 1](a);
      }
    if (xx <= 0.0) continue;
    const double rho = std::clamp(xy / xx, -0.97, 0.97);
    double innovation = 0.0;
    long count = 0;
    for (std::size_t i = 1; i < t.score.size(); ++i)
      if (t.grid[i] - t.grid[i - 1] == odmf) {
        const double e = t.score[i](a) - rho * t.score[i - 1](a);
        innovation += e * e;
        ++count;
      }
    const double s2 = innovation / static_cast<double>(std::max(count, 1L));
    numerator += 4.0 * rho * rho * s2 * s2 / (std::pow(1.0 - rho, 6) * (1.0 + rho) * (1.0 + rho));
    denominator += s2 * s2 / std::pow(1.0 - rho, 4);
  }
  if (denominator <= 0.0) return 0;
  const auto n = static_cast<double>(t.score.size());
  const int lags = static_cast<int>(std::ceil(1.1447 * std::cbrt(numerator / denominator * n)));
  return std::clamp(lags, 0, std::max(0, static_cast<int>(t.score.size()) / 4));
}

// S = sum_t s_t s_t' + sum_{l=1..L} (1 - l/(L+1)) sum_t (s_t s_{t-l}' + s_{t-l} s_t'), pairs
// taken by their grid distance (rows of different segments are never l steps apart by chance
// of the index: a gap is longer than the filter's padding).
Eigen::MatrixXd newey_west(const TimeScores& t, int lags, int odmf) {
  const Eigen::Index k = t.score.empty() ? 0 : t.score.front().size();
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(k, k);
  for (std::size_t i = 0; i < t.score.size(); ++i) {
    s.noalias() += t.score[i] * t.score[i].transpose();
    for (std::size_t j = i; j-- > 0;) {
      const Eigen::Index distance = (t.grid[i] - t.grid[j]) / odmf;
      if (distance > lags) break;
      const double weight = 1.0 - static_cast<double>(distance) / static_cast<double>(lags + 1);
      const Eigen::MatrixXd cross = t.score[i] * t.score[j].transpose();
      s.noalias() += weight * (cross + cross.transpose());
    }
  }
  return s;
}

}  // namespace

TimeScores sum_by_grid(const std::vector<Eigen::Index>& grid, const Eigen::MatrixXd& scores) {
  std::map<Eigen::Index, Eigen::VectorXd> by_grid;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    auto [it, fresh] = by_grid.try_emplace(grid[i], Eigen::VectorXd::Zero(scores.cols()));
    it->second += scores.row(static_cast<Eigen::Index>(i)).transpose();
  }
  TimeScores out;
  for (auto& [at, value] : by_grid) {
    out.grid.push_back(at);
    out.score.push_back(std::move(value));
  }
  return out;
}

Eigen::MatrixXd long_run_covariance(TimeScores t, int odmf, int& bandwidth) {
  const Eigen::VectorXd unit = to_unit_scale(t);
  const Eigen::MatrixXd whitening = prewhiten(t, odmf);
  bandwidth = andrews_bandwidth(t, odmf);
  const Eigen::MatrixXd recolour =
      (Eigen::MatrixXd::Identity(whitening.rows(), whitening.cols()) - whitening).completeOrthogonalDecomposition().pseudoInverse();
  return unit.asDiagonal() * (recolour * newey_west(t, bandwidth, odmf) * recolour.transpose()) * unit.asDiagonal();
}

WaldTest hac_wald_test(const FoldedRows& rows, const Eigen::VectorXd& x, const std::vector<double>& weights,
                       Eigen::Index first, Eigen::Index end, int odmf) {
  WaldTest result;
  result.degrees_of_freedom = static_cast<int>(end - first);
  std::vector<Eigen::Index> used;
  std::vector<Eigen::Index> tested;  // positions within `used`
  // A tested column that is not identifiable (a road profile's knots sum to the offset's
  // column) is left out: the test is on the candidate's identifiable columns.
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    if (!std::isfinite(x(j))) continue;
    if (j >= first && j < end) tested.push_back(static_cast<Eigen::Index>(used.size()));
    used.push_back(j);
  }
  if (tested.empty()) return result;
  result.degrees_of_freedom = static_cast<int>(tested.size());
  Eigen::MatrixXd information;
  const Eigen::MatrixXd meat =
      long_run_covariance(scores_by_time(rows, x, weights, used, information), odmf, result.bandwidth);
  // The bread, inverted on unit-scaled columns: the columns' units differ by many orders (a
  // squared grade in rad^2 beside a force), and a rank threshold on the raw matrix would drop a
  // small but identifiable column and call its variance 0.
  const Eigen::VectorXd scale = information.diagonal().cwiseMax(std::numeric_limits<double>::min()).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * information * scale.asDiagonal();
  const Eigen::LDLT<Eigen::MatrixXd> bread(scaled);
  if (bread.info() != Eigen::Success || !bread.isPositive()) return result;
  const Eigen::MatrixXd inverse =
      scale.asDiagonal() * bread.solve(Eigen::MatrixXd::Identity(scaled.rows(), scaled.cols())) * scale.asDiagonal();
  const Eigen::MatrixXd covariance = inverse * meat * inverse;
  const auto q = static_cast<Eigen::Index>(tested.size());
  Eigen::MatrixXd v(q, q);
  Eigen::VectorXd b(q);
  for (Eigen::Index a = 0; a < q; ++a) {
    b(a) = x(used[static_cast<std::size_t>(tested[static_cast<std::size_t>(a)])]);
    for (Eigen::Index c = 0; c < q; ++c)
      v(a, c) = covariance(tested[static_cast<std::size_t>(a)], tested[static_cast<std::size_t>(c)]);
  }
  result.stds = Eigen::VectorXd::Constant(end - first, std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index a = 0; a < q; ++a)
    result.stds(used[static_cast<std::size_t>(tested[static_cast<std::size_t>(a)])] - first) = std::sqrt(std::max(0.0, v(a, a)));
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(v);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || (ldlt.vectorD().array() <= 0.0).any()) return result;
  result.statistic = b.dot(ldlt.solve(b));
  result.first_std = std::sqrt(v(0, 0));
  result.testable = std::isfinite(result.statistic);
  if (result.testable)
    result.p_value = boost::math::cdf(boost::math::complement(
        boost::math::chi_squared(static_cast<double>(q)), std::max(0.0, result.statistic)));
  return result;
}

}  // namespace dynid::residual::detail
