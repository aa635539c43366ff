#include "dynid/residual/model_fit.hpp"

#include <cmath>

#include "folded_rows.hpp"

namespace dynid::residual {
namespace {

double ratio_root(double numerator, double denominator) {
  return denominator > 0.0 ? std::sqrt(numerator / denominator) : 0.0;
}

// The residual on the decimated grid, gaps reading 0, for the spectrum.
Spectrum residual_spectrum(const std::vector<Eigen::Index>& grid, const Eigen::VectorXd& r,
                           int odmf, double sample_rate_hz) {
  if (grid.size() < 4) return {};
  const Eigen::Index first = grid.front() / odmf;
  Eigen::VectorXd uniform = Eigen::VectorXd::Zero(grid.back() / odmf - first + 1);
  for (std::size_t i = 0; i < grid.size(); ++i) uniform(grid[i] / odmf - first) = r(static_cast<Eigen::Index>(i));
  return amplitude_spectrum(uniform, static_cast<double>(odmf) / sample_rate_hz);
}

ResidualSeries series_of(const detail::FoldedRows& rows, const detail::Evaluation& e, std::size_t g,
                         int odmf, double sample_rate_hz) {
  const auto width = static_cast<Eigen::Index>(rows.parameters.size());
  const std::vector<double>& v = rows.collected.values[g];
  const Eigen::Index m = static_cast<Eigen::Index>(v.size()) / (width + 1);
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> all(
      v.data(), m, width + 1);
  ResidualSeries s;
  s.group = rows.groups[g];
  s.time_s = rows.collected.time_s[g];
  s.grid_index = rows.collected.grid_index[g];
  s.measured = all.col(width);
  s.residual = s.measured - all.leftCols(width) * e.x;
  const Eigen::Index effect_columns = rows.last_effect_end - rows.last_effect_first;
  if (effect_columns > 0) {
    s.effect_contribution = all.middleCols(rows.last_effect_first, effect_columns) *
                            e.x.segment(rows.last_effect_first, effect_columns);
    // A road profile's level is not separable from an offset column (its hats sum to 1).
    if (rows.last_effect_is_profile && s.effect_contribution.size() > 0)
      s.effect_contribution.array() -= s.effect_contribution.mean();
  }
  s.spectrum = residual_spectrum(rows.collected.grid_index[g], s.residual, odmf, sample_rate_hz);
  return s;
}

double group_sigma(const std::vector<ls::GroupStatistics>& groups, const std::string& name) {
  for (const ls::GroupStatistics& g : groups)
    if (g.name == name) return g.weight > 0.0 ? 1.0 / g.weight : 0.0;
  return 0.0;
}

}  // namespace

ModelFit fit_model(const model::Model& model, const std::vector<std::string>& effects,
                   const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                   int odmf, const FitOptions& options) {
  const detail::FoldedRows rows =
      detail::fold_rows(model, effects, run, sample_rate_hz, odmf, options, options.series);
  const detail::Evaluation e = detail::evaluate(rows, {}, options.group_weights);
  ModelFit fit;
  fit.model = model.name();
  fit.effects = effects;
  fit.parameters = rows.parameters;
  fit.estimate = e.all;
  fit.column_norms = e.column_norms;
  fit.group_statistics = e.group_statistics;
  fit.profile_knots_m = rows.profile_knots_m;
  for (std::size_t g = 0; g < rows.groups.size(); ++g) {
    GroupFit gf;
    gf.group = rows.groups[g];
    gf.rows = e.rows[g];
    gf.sigma = group_sigma(e.group_statistics, gf.group);
    gf.rms_in_sample = ratio_root(e.rss_in[g], static_cast<double>(e.rows[g]));
    gf.relative_norm_in_sample = ratio_root(e.rss_in[g], e.ss_measured[g]);
    gf.rms_held_out = ratio_root(e.rss_out[g], static_cast<double>(e.rows[g]));
    gf.relative_norm_held_out = ratio_root(e.rss_out[g], e.ss_measured[g]);
    fit.groups.push_back(gf);
  }
  const auto total = static_cast<double>(e.total_rows());
  fit.weighted_rms_in_sample = ratio_root(e.weighted_in(), total);
  fit.weighted_rms_held_out = ratio_root(e.weighted_out(), total);
  if (options.series) {
    for (std::size_t g = 0; g < rows.groups.size(); ++g)
      if (e.rows[g] > 0) fit.series.push_back(series_of(rows, e, g, odmf, sample_rate_hz));
  }
  return fit;
}

}  // namespace dynid::residual
