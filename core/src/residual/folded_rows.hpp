#pragma once
// Internal: the rows of one model configuration over a recorded run, folded into one set of
// equation-group accumulators per cross-validation fold, and their evaluation (in sample and
// held out) on any prefix-free column selection. Contracts of the public headers apply.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/ls/equation_groups.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::residual::detail {

/// Every kept row, per group, for the time series (W and y as folded).
struct CollectedRows {
  std::vector<std::vector<double>> time_s;          // per group
  std::vector<std::vector<Eigen::Index>> grid_index;  // per group, run grid index
  std::vector<std::vector<double>> values;          // per group, rows of [w y] back to back
};

/// The rows a model configuration keeps on a run: per segment, per equation group, the segment
/// sample index of every row (increasing).
using RowSelection = std::vector<std::vector<std::vector<Eigen::Index>>>;

struct FoldedRows {
  std::vector<model::ParameterInfo> parameters;
  std::vector<std::string> groups;
  std::vector<ls::EquationGroups> folds;
  std::vector<double> profile_knots_m;  // empty without a road profile
  // Columns [last_effect_first, last_effect_end) are the last effect given (empty range
  // without effects).
  Eigen::Index last_effect_first = 0;
  Eigen::Index last_effect_end = 0;
  bool last_effect_is_profile = false;
  CollectedRows collected;
  /// Rows the configuration builds that a restriction (fold_rows' `only`) left out.
  std::uint64_t rows_outside = 0;
  std::uint64_t rows() const;
};

/// `effects`: model and dictionary effects, and at most one road-profile effect (its columns
/// come last). `only`, when given, keeps only the rows it lists (a candidate judged on the
/// declared model's rows); the others are counted in rows_outside. Throws InputError (missing
/// channel, unknown effect, no row on the grid).
FoldedRows fold_rows(const model::Model& model, const std::vector<std::string>& effects,
                     const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                     int odmf, const FitOptions& options, bool collect,
                     const RowSelection* only = nullptr);

/// Whether the rows of fold_rows(model, effects, run, ..., collect = true) (`base`) read the
/// channel `channel` of the run or `derivative` (the derivative preprocessing made from it; empty
/// when the run announces its own): false only when, with every valid sample of both moved by
/// a pseudo-random amount of up to `scale` (their noise), the same rows come out bit for bit.
/// Its cost is building the rows once, without their fit: the noise floor asks it of every
/// channel the run has, most of which a model does not read, instead of drawing noise for each.
bool reads_channel(const FoldedRows& base, const model::Model& model,
                   const std::vector<std::string>& effects,
                   const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                   int odmf, const FitOptions& options, const std::string& channel,
                   const std::string& derivative, double scale);

/// The rows `model` with `effects` (a road profile or a varying parameter among them changes no
/// row; a delay does) keeps on the decimation grid of `run`. Throws InputError as fold_rows.
RowSelection kept_rows(const model::Model& model, const std::vector<std::string>& effects,
                       const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz, int odmf);

struct Evaluation {
  ls::Estimate all;
  Eigen::VectorXd column_norms;        // of the weighted system of `all` (parameter status)
  std::vector<ls::GroupStatistics> group_statistics;
  Eigen::VectorXd x;                   // the in-sample solution, 0 where not identifiable
  std::vector<double> weights;         // per group (fixed or the fit's own 1/sigma_j)
  std::vector<double> estimator_weights;  // per group: the fit's own 1/sigma_j (x solves with these)
  std::vector<std::uint64_t> rows;     // per group
  std::vector<double> ss_measured;     // per group ||y||^2
  std::vector<double> rss_in;          // per group
  std::vector<double> rss_out;         // per group, summed over folds
  std::vector<double> fold_weighted_out;  // per fold sum_g w_g^2 rss_out; NaN: fold not predicted
  double weighted_in() const;          // sum_g w_g^2 rss_in
  double weighted_out() const;
  std::uint64_t total_rows() const;
};

/// Evaluates the columns `columns` (increasing; empty = all) of `rows`. `weights` per group of
/// rows.groups (empty: the in-sample fit's own DYCARO weights).
Evaluation evaluate(const FoldedRows& rows, const std::vector<Eigen::Index>& columns,
                    const std::vector<double>& weights);

/// The residual y - W x of every collected row, per group, with its grid index (increasing).
using GridResiduals = std::vector<std::vector<std::pair<Eigen::Index, double>>>;
GridResiduals residuals_at(const FoldedRows& rows, const Eigen::VectorXd& x);

/// `base` (collected) with one more column, `column[g][i]` for collected row i of group g
/// (NaN: the row is left out), folded again into the cross-validation folds of `cv`. The new
/// column is the last effect.
FoldedRows with_extra_column(const FoldedRows& base, const std::vector<std::vector<double>>& column,
                             const model::ParameterInfo& info, const CrossValidation& cv);

/// The solution with NaN (not identifiable) entries set to 0: the base-parameter solution.
Eigen::VectorXd base_solution(const ls::Estimate& estimate);

/// base_solution of the fit on all rows: evaluate(rows, ...).x without the held-out fits (a
/// noise draw or a located effect needs the solution only).
Eigen::VectorXd solution(const FoldedRows& rows);

/// The weighted least-squares regression of collected column `column` on the collected columns
/// `on`, each group's rows weighted by `weights` (per group of rows.groups): the coefficients b
/// of the omitted-variable identity, x_without = x_with + b * coefficient (effect_screen.hpp).
Eigen::VectorXd regress_column(const FoldedRows& rows, Eigen::Index column, const std::vector<Eigen::Index>& on,
                               const std::vector<double>& weights);

}  // namespace dynid::residual::detail
