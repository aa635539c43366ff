#include "folded_rows.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/QR>

#include "dynid/cancellation.hpp"
#include "dynid/error.hpp"
#include "dynid/model/parameter_status.hpp"
#include "dynid/residual/road_profile.hpp"
#include "dynid/residual/sensor_offset.hpp"
#include "dynid/residual/signal_delay.hpp"
#include "dynid/residual/varying_parameter.hpp"

namespace dynid::residual::detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string format_metres(double m) {
  return std::to_string(static_cast<long long>(std::llround(m))) + "m";
}

// The parameters a road profile adds: one per knot and group.
void add_profile_parameters(const std::string& effect, const std::vector<std::string>& groups,
                            const RoadProfile& profile, FoldedRows& out) {
  for (const std::string& g : groups)
    for (Eigen::Index k = 0; k < profile.knots(); ++k) {
      const std::string suffix = groups.size() > 1 ? "@" + g : "";
      out.parameters.push_back({effect + suffix + "@" + format_metres(profile.knot_distance(k)), "",
                                "the road profile's contribution at this knot (y units)",
                                std::nullopt});
    }
  for (Eigen::Index k = 0; k < profile.knots(); ++k) out.profile_knots_m.push_back(profile.knot_distance(k));
}

// Row buffers of one segment, per fold and group, folded in one batch each.
struct SegmentBuffers {
  std::vector<std::vector<std::vector<double>>> values;  // [fold][group] rows of [w y]
  SegmentBuffers(int folds, std::size_t groups)
      : values(static_cast<std::size_t>(folds), std::vector<std::vector<double>>(groups)) {}
  void fold_into(std::vector<ls::EquationGroups>& folds, Eigen::Index width) {
    for (std::size_t f = 0; f < values.size(); ++f)
      for (std::size_t g = 0; g < values[f].size(); ++g) {
        std::vector<double>& v = values[f][g];
        if (v.empty()) continue;
        const Eigen::Index m = static_cast<Eigen::Index>(v.size()) / (width + 1);
        const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> rows(
            v.data(), m, width + 1);
        folds[f].group(g).fold_augmented(rows);
        v.clear();
      }
  }
};

}  // namespace

std::uint64_t FoldedRows::rows() const {
  std::uint64_t n = 0;
  for (const ls::EquationGroups& f : folds)
    for (std::size_t g = 0; g < f.size(); ++g) n += f.group(g).row_count();
  return n;
}

namespace {

std::vector<Eigen::Index> decimation_grid(const ingest::PreprocessedSegment& seg, int odmf) {
  std::vector<Eigen::Index> kept;  // rows are built at the decimation grid's samples only
  for (Eigen::Index i = 0; i < seg.channels.samples(); ++i)
    if (ingest::row_at(seg, i, odmf)) kept.push_back(i);
  return kept;
}

// The effects the model itself builds (a road profile, a varying parameter or a delay is
// fold_rows' own).
std::vector<std::string> without_profiles(const std::vector<std::string>& effects) {
  std::vector<std::string> out;
  for (const std::string& e : effects)
    if (!is_road_profile_effect(e) && !is_varying_effect(e) && !is_delay_effect(e) && !is_offset_effect(e))
      out.push_back(e);
  return out;
}

// The run as the effects that change signals say it was measured: delayed channels read on
// time, offset channels read without their offset.
std::vector<ingest::PreprocessedSegment> signals_corrected(const std::vector<ingest::PreprocessedSegment>& input,
                                                           const std::vector<std::string>& effects,
                                                           double sample_rate_hz) {
  std::vector<SignalDelay> delays;
  std::vector<SensorOffset> offsets;
  for (const std::string& e : effects) {
    if (is_delay_effect(e)) delays.push_back(parse_delay_effect(e, sample_rate_hz));
    if (is_offset_effect(e)) offsets.push_back(parse_offset_effect(e));
  }
  if (delays.empty() && offsets.empty()) return input;
  const std::vector<ingest::PreprocessedSegment> on_time = delays.empty() ? input : delayed(input, delays);
  return offsets.empty() ? on_time : offset_corrected(on_time, offsets);
}

bool listed(const std::vector<Eigen::Index>& sorted, Eigen::Index sample) {
  return std::binary_search(sorted.begin(), sorted.end(), sample);
}

}  // namespace

RowSelection kept_rows(const model::Model& model, const std::vector<std::string>& effects,
                       const std::vector<ingest::PreprocessedSegment>& input, double sample_rate_hz, int odmf) {
  cancellation_point();  // each fit of the residual loop passes here
  const std::vector<std::string> model_effects = without_profiles(effects);
  const std::vector<ingest::PreprocessedSegment> run = signals_corrected(input, effects, sample_rate_hz);
  RowSelection out(run.size(), std::vector<std::vector<Eigen::Index>>(model.groups().size()));
  for (std::size_t s = 0; s < run.size(); ++s) {
    const std::vector<Eigen::Index> kept = decimation_grid(run[s], odmf);
    if (kept.empty()) continue;
    const std::vector<model::GroupRows> built = model.rows_at(run[s].channels, kept, model_effects);
    for (std::size_t g = 0; g < built.size() && g < out[s].size(); ++g) out[s][g] = built[g].samples;
  }
  return out;
}

namespace {

// What each varying parameter's column multiplies, per segment, centred on its run mean over
// valid samples (varying_parameter.hpp): a dependence's channel, or a cumulative quantity
// integrated from the run's start (a gap between segments adds nothing). Empty for a drift with
// time or a step. InputError when the run lacks a channel.
std::vector<std::vector<Eigen::VectorXd>> centred_series(const std::vector<VaryingParameter>& varying,
                                                         const std::vector<ingest::PreprocessedSegment>& run) {
  std::vector<std::vector<Eigen::VectorXd>> out(varying.size());
  for (std::size_t v = 0; v < varying.size(); ++v) {
    const VaryingParameter& p = varying[v];
    if (p.kind != VaryingParameter::Kind::kChannel && p.kind != VaryingParameter::Kind::kCumulative) continue;
    double sum = 0.0, count = 0.0, accumulated = 0.0;
    for (const ingest::PreprocessedSegment& seg : run) {
      Eigen::VectorXd x;
      if (p.kind == VaryingParameter::Kind::kChannel) {
        if (!seg.channels.has(p.channel))
          throw InputError("effect 'depends:" + p.parameter + "~" + p.channel + "': the run has no channel '" + p.channel + "'");
        x = seg.channels[p.channel];
      } else {
        const Eigen::VectorXd rate = cumulative_rate(p.channel, seg.channels);
        x.resize(rate.size());
        for (Eigen::Index k = 0; k < rate.size(); ++k) x(k) = accumulated += rate(k) * seg.channels.sample_period();
      }
      for (Eigen::Index k = 0; k < x.size(); ++k)
        if (seg.channels.valid(k) && std::isfinite(x(k))) sum += x(k), count += 1.0;
      out[v].push_back(std::move(x));
    }
    const double mean = count > 0.0 ? sum / count : 0.0;
    for (Eigen::VectorXd& x : out[v]) x.array() -= mean;
  }
  return out;
}

}  // namespace

namespace {

// fold_rows, or (`fold` false) its collected rows alone, nothing folded.
FoldedRows build_rows(const model::Model& model, const std::vector<std::string>& effects,
                      const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                      int odmf, const FitOptions& options, bool collect, const RowSelection* only,
                      bool fold) {
  cancellation_point();  // each fit of the residual loop passes here
  options.cross_validation.validate();
  if (odmf < 1) throw InputError("residual analysis: odmf " + std::to_string(odmf) + " < 1");
  std::vector<std::string> model_effects;
  std::vector<VaryingParameter> varying;
  std::string profile_effect;
  for (const std::string& e : effects) {
    if (is_varying_effect(e)) {
      varying.push_back(parse_varying_effect(e, model));
    } else if (is_delay_effect(e) || is_offset_effect(e)) {
      continue;  // signals_corrected
    } else if (!is_road_profile_effect(e)) {
      model_effects.push_back(e);
    } else if (profile_effect.empty()) {
      profile_effect = e;
    } else {
      throw InputError("residual analysis: at most one road profile effect (" + profile_effect +
                       ", " + e + ")");
    }
  }
  // Columns: the model's (parameters, then its effects), the varying parameters', the profile's.
  FoldedRows out;
  out.parameters = model.parameters_with(model_effects);
  out.groups = model.groups();
  const auto model_width = static_cast<Eigen::Index>(out.parameters.size());
  for (const VaryingParameter& v : varying) out.parameters.push_back(varying_parameter_info(v, model));
  const auto varying_end = static_cast<Eigen::Index>(out.parameters.size());
  std::unique_ptr<RoadProfile> profile;
  if (!profile_effect.empty()) {
    profile = std::make_unique<RoadProfile>(run, 1.0 / sample_rate_hz, options.profile_knot_spacing_m,
                                            options.cross_validation.block_seconds);
    add_profile_parameters(profile_effect, out.groups, *profile, out);
  }
  const auto width = static_cast<Eigen::Index>(out.parameters.size());
  if (effects.empty()) {
    out.last_effect_first = out.last_effect_end = width;
  } else if (is_road_profile_effect(effects.back())) {
    out.last_effect_first = varying_end;
    out.last_effect_end = width;
    out.last_effect_is_profile = true;
  } else if (is_varying_effect(effects.back())) {
    out.last_effect_first = varying_end - 1;
    out.last_effect_end = varying_end;
  } else if (is_delay_effect(effects.back()) || is_offset_effect(effects.back())) {  // no column: the rows change
    out.last_effect_first = out.last_effect_end = width;
  } else {
    const std::vector<std::string> before(model_effects.begin(), model_effects.end() - 1);
    out.last_effect_first = static_cast<Eigen::Index>(model.parameters_with(before).size());
    out.last_effect_end = model_width;
  }
  const double t_mid = run.empty() ? 0.0
                                   : 0.5 * static_cast<double>(run.front().first + run.back().first +
                                                               run.back().channels.samples() - 1) /
                                         sample_rate_hz;
  const std::size_t group_count = out.groups.size();
  out.folds.assign(static_cast<std::size_t>(options.cross_validation.folds),
                   ls::EquationGroups(width, out.groups, options.precision));
  if (collect) {
    out.collected.time_s.resize(group_count);
    out.collected.grid_index.resize(group_count);
    out.collected.values.resize(group_count);
  }
  SegmentBuffers buffers(options.cross_validation.folds, group_count);
  std::vector<double> row(static_cast<std::size_t>(width + 1));
  // A copy of the run only when an effect changes its signals (the screen folds hundreds of times).
  const bool corrected = std::any_of(effects.begin(), effects.end(),
                                     [](const std::string& e) { return is_delay_effect(e) || is_offset_effect(e); });
  const std::vector<ingest::PreprocessedSegment> corrected_run =
      corrected ? signals_corrected(run, effects, sample_rate_hz) : std::vector<ingest::PreprocessedSegment>{};
  const std::vector<ingest::PreprocessedSegment>& rows_run = corrected ? corrected_run : run;
  const std::vector<std::vector<Eigen::VectorXd>> centred = centred_series(varying, rows_run);
  for (std::size_t s = 0; s < rows_run.size(); ++s) {
    const ingest::PreprocessedSegment& seg = rows_run[s];
    const std::vector<Eigen::Index> kept = decimation_grid(seg, odmf);
    if (kept.empty()) continue;
    const std::vector<model::GroupRows> built = model.rows_at(seg.channels, kept, model_effects);
    for (std::size_t g = 0; g < built.size(); ++g) {
      const model::GroupRows& gr = built[g];
      for (std::size_t i = 0; i < gr.samples.size(); ++i) {
        const Eigen::Index sample = gr.samples[i];
        if (only != nullptr && !listed((*only)[s][g], sample)) {
          ++out.rows_outside;
          continue;
        }
        std::fill(row.begin(), row.end(), 0.0);
        for (Eigen::Index j = 0; j < model_width; ++j)
          row[static_cast<std::size_t>(j)] = gr.W(static_cast<Eigen::Index>(i), j);
        const Eigen::Index grid_at = seg.first + sample;
        const double time_at = static_cast<double>(grid_at) / sample_rate_hz;
        for (std::size_t v = 0; v < varying.size(); ++v) {
          const double x = centred[v].empty() ? 0.0 : centred[v][s](sample);
          row[static_cast<std::size_t>(model_width) + v] =
              varying_column(varying[v], gr.W(static_cast<Eigen::Index>(i), varying[v].column), time_at, t_mid, x);
        }
        if (profile)
          profile->hats(profile->distance(s, sample),
                        row.data() + varying_end + static_cast<Eigen::Index>(g) * profile->knots());
        row.back() = gr.y(static_cast<Eigen::Index>(i));
        const Eigen::Index grid = seg.first + sample;
        const double t = static_cast<double>(grid) / sample_rate_hz;
        if (fold) {
          auto& dest =
              buffers.values[static_cast<std::size_t>(options.cross_validation.fold_of(t))][g];
          dest.insert(dest.end(), row.begin(), row.end());
        }
        if (collect) {
          out.collected.time_s[g].push_back(t);
          out.collected.grid_index[g].push_back(grid);
          out.collected.values[g].insert(out.collected.values[g].end(), row.begin(), row.end());
        }
      }
    }
    if (fold) buffers.fold_into(out.folds, width);
  }
  const bool none = fold ? out.rows() == 0
                         : std::all_of(out.collected.values.begin(), out.collected.values.end(),
                                       [](const std::vector<double>& v) { return v.empty(); });
  if (none)
    throw InputError("model " + model.name() +
                     ": no row on the run (masking, or no valid segment)");
  return out;
}

}  // namespace

FoldedRows fold_rows(const model::Model& model, const std::vector<std::string>& effects,
                     const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                     int odmf, const FitOptions& options, bool collect, const RowSelection* only) {
  return build_rows(model, effects, run, sample_rate_hz, odmf, options, collect, only, true);
}

bool reads_channel(const FoldedRows& base, const model::Model& model,
                   const std::vector<std::string>& effects,
                   const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                   int odmf, const FitOptions& options, const std::string& channel,
                   const std::string& derivative, double scale) {
  // Uniform in [-scale, scale) from a fixed linear congruential sequence: no model reads a
  // channel in a way that such a perturbation leaves every row unchanged (a constant would pass
  // through differences, a smooth one through a filter).
  std::uint64_t state = 0x9e3779b97f4a7c15ULL;
  const auto moved = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd out = x;
    for (Eigen::Index k = 0; k < out.size(); ++k) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      out(k) += scale * (static_cast<double>(state >> 11) * 0x1.0p-52 - 1.0);
    }
    return out;
  };
  std::vector<ingest::PreprocessedSegment> changed = run;
  for (ingest::PreprocessedSegment& s : changed)
    for (const std::string& name : {channel, derivative})
      if (!name.empty() && s.channels.has(name)) s.channels.replace(name, moved(s.channels[name]));
  try {
    const FoldedRows rows =
        build_rows(model, effects, changed, sample_rate_hz, odmf, options, true, nullptr, false);
    return rows.parameters.size() != base.parameters.size() ||
           rows.collected.values != base.collected.values ||
           rows.collected.grid_index != base.collected.grid_index;
  } catch (const InputError&) {
    return true;  // the rows cannot be built with the channel moved: they read it
  }
}

GridResiduals residuals_at(const FoldedRows& rows, const Eigen::VectorXd& x) {
  const auto width = static_cast<Eigen::Index>(rows.parameters.size());
  GridResiduals out(rows.collected.values.size());
  for (std::size_t g = 0; g < out.size(); ++g) {
    const std::vector<double>& v = rows.collected.values[g];
    const Eigen::Index m = static_cast<Eigen::Index>(v.size()) / (width + 1);
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> all(
        v.data(), m, width + 1);
    const Eigen::VectorXd r = all.col(width) - all.leftCols(width) * x;
    for (Eigen::Index i = 0; i < m; ++i)
      out[g].emplace_back(rows.collected.grid_index[g][static_cast<std::size_t>(i)], r(i));
    std::sort(out[g].begin(), out[g].end());
  }
  return out;
}

FoldedRows with_extra_column(const FoldedRows& base, const std::vector<std::vector<double>>& column,
                             const model::ParameterInfo& info, const CrossValidation& cv) {
  const auto width = static_cast<Eigen::Index>(base.parameters.size());
  FoldedRows out;
  out.parameters = base.parameters;
  out.parameters.push_back(info);
  out.groups = base.groups;
  out.last_effect_first = width;
  out.last_effect_end = width + 1;
  out.rows_outside = base.rows_outside;
  out.folds.assign(static_cast<std::size_t>(cv.folds), ls::EquationGroups(width + 1, out.groups));
  out.collected.time_s.resize(base.groups.size());
  out.collected.grid_index.resize(base.groups.size());
  out.collected.values.resize(base.groups.size());
  SegmentBuffers buffers(cv.folds, base.groups.size());
  std::vector<double> row(static_cast<std::size_t>(width + 2));
  for (std::size_t g = 0; g < base.groups.size(); ++g) {
    const std::vector<double>& v = base.collected.values[g];
    for (std::size_t i = 0; i < base.collected.time_s[g].size(); ++i) {
      if (!std::isfinite(column[g][i])) continue;
      const double* source = v.data() + i * static_cast<std::size_t>(width + 1);
      std::copy(source, source + width, row.begin());
      row[static_cast<std::size_t>(width)] = column[g][i];
      row.back() = source[width];
      const double t = base.collected.time_s[g][i];
      auto& dest = buffers.values[static_cast<std::size_t>(cv.fold_of(t))][g];
      dest.insert(dest.end(), row.begin(), row.end());
      out.collected.time_s[g].push_back(t);
      out.collected.grid_index[g].push_back(base.collected.grid_index[g][i]);
      out.collected.values[g].insert(out.collected.values[g].end(), row.begin(), row.end());
    }
  }
  buffers.fold_into(out.folds, width + 1);
  if (out.rows() == 0) throw InputError("residual analysis: no row left for '" + info.name + "'");
  return out;
}

Eigen::VectorXd regress_column(const FoldedRows& rows, Eigen::Index column, const std::vector<Eigen::Index>& on,
                               const std::vector<double>& weights) {
  const auto stride = static_cast<Eigen::Index>(rows.parameters.size()) + 1;
  Eigen::Index total = 0;
  for (const std::vector<double>& v : rows.collected.values) total += static_cast<Eigen::Index>(v.size()) / stride;
  Eigen::MatrixXd a(total, static_cast<Eigen::Index>(on.size()));
  Eigen::VectorXd c(total);
  Eigen::Index i = 0;
  for (std::size_t g = 0; g < rows.collected.values.size(); ++g) {
    const std::vector<double>& v = rows.collected.values[g];
    const double w = g < weights.size() ? weights[g] : 1.0;
    for (std::size_t at = 0; at < v.size(); at += static_cast<std::size_t>(stride), ++i) {
      for (std::size_t j = 0; j < on.size(); ++j)
        a(i, static_cast<Eigen::Index>(j)) = w * v[at + static_cast<std::size_t>(on[j])];
      c(i) = w * v[at + static_cast<std::size_t>(column)];
    }
  }
  return a.colPivHouseholderQr().solve(c);
}

Eigen::VectorXd base_solution(const ls::Estimate& estimate) {
  Eigen::VectorXd x = estimate.value;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!std::isfinite(x(i))) x(i) = 0.0;
  return x;
}

namespace {

ls::EquationGroups selected(const ls::EquationGroups& groups, const std::vector<Eigen::Index>& columns,
                            const std::vector<std::string>& names) {
  if (columns.empty()) return groups;
  ls::EquationGroups out(static_cast<Eigen::Index>(columns.size()), names);
  for (std::size_t g = 0; g < groups.size(); ++g)
    if (groups.group(g).row_count() > 0) out.group(g) = groups.group(g).select_columns(columns);
  return out;
}

ls::EquationGroups merged(const std::vector<ls::EquationGroups>& folds, int except,
                          const std::vector<std::string>& names) {
  ls::EquationGroups out(folds.front().group(0).parameter_count(), names);
  for (std::size_t f = 0; f < folds.size(); ++f) {
    if (static_cast<int>(f) == except) continue;
    for (std::size_t g = 0; g < names.size(); ++g) out.group(g).merge(folds[f].group(g));
  }
  return out;
}

std::uint64_t rows_of(const ls::EquationGroups& groups) {
  std::uint64_t n = 0;
  for (std::size_t g = 0; g < groups.size(); ++g) n += groups.group(g).row_count();
  return n;
}

std::vector<double> own_weights(const std::vector<ls::GroupStatistics>& groups,
                                const std::vector<std::string>& names) {
  std::vector<double> w(names.size(), 0.0);
  for (const ls::GroupStatistics& s : groups)
    for (std::size_t g = 0; g < names.size(); ++g)
      if (names[g] == s.name) w[g] = s.weight;
  return w;
}

}  // namespace

double Evaluation::weighted_in() const {
  double s = 0.0;
  for (std::size_t g = 0; g < rss_in.size(); ++g) s += weights[g] * weights[g] * rss_in[g];
  return s;
}

double Evaluation::weighted_out() const {
  double s = 0.0;
  for (std::size_t g = 0; g < rss_out.size(); ++g) s += weights[g] * weights[g] * rss_out[g];
  return s;
}

std::uint64_t Evaluation::total_rows() const {
  std::uint64_t n = 0;
  for (std::uint64_t r : rows) n += r;
  return n;
}

Eigen::VectorXd solution(const FoldedRows& rows) {
  return base_solution(merged(rows.folds, -1, rows.groups).estimate().estimate);
}

Evaluation evaluate(const FoldedRows& rows, const std::vector<Eigen::Index>& columns,
                    const std::vector<double>& weights) {
  const std::vector<std::string>& names = rows.groups;
  if (!weights.empty() && weights.size() != names.size())
    throw InputError("residual analysis: " + std::to_string(weights.size()) + " group weights for " +
                     std::to_string(names.size()) + " equation groups");
  std::vector<ls::EquationGroups> folds;
  for (const ls::EquationGroups& f : rows.folds) folds.push_back(selected(f, columns, names));
  Evaluation e;
  const ls::EquationGroups all = merged(folds, -1, names);
  ls::WeightedEstimate fit = all.estimate();
  e.column_norms = model::column_norms(fit.weighted);
  e.all = std::move(fit.estimate);
  e.group_statistics = std::move(fit.groups);
  e.x = base_solution(e.all);
  e.estimator_weights = own_weights(e.group_statistics, names);
  e.weights = weights.empty() ? e.estimator_weights : weights;
  const std::size_t group_count = names.size();
  e.rows.assign(group_count, 0);
  e.ss_measured.assign(group_count, 0.0);
  e.rss_in.assign(group_count, 0.0);
  e.rss_out.assign(group_count, 0.0);
  for (std::size_t g = 0; g < group_count; ++g) {
    const ls::Accumulator& a = all.group(g);
    e.rows[g] = a.row_count();
    if (a.row_count() == 0) continue;
    e.ss_measured[g] = a.measured_norm() * a.measured_norm();
    const double r = a.residual_norm_at(e.x);
    e.rss_in[g] = r * r;
  }
  for (std::size_t k = 0; k < folds.size(); ++k) {
    const ls::EquationGroups train = merged(folds, static_cast<int>(k), names);
    if (rows_of(train) == 0 || rows_of(folds[k]) == 0) {
      e.fold_weighted_out.push_back(kNaN);
      continue;
    }
    const Eigen::VectorXd xk = base_solution(train.estimate().estimate);
    double weighted = 0.0;
    for (std::size_t g = 0; g < group_count; ++g) {
      const ls::Accumulator& test = folds[k].group(g);
      if (test.row_count() == 0) continue;
      const double r = test.residual_norm_at(xk);
      e.rss_out[g] += r * r;
      weighted += e.weights[g] * e.weights[g] * r * r;
    }
    e.fold_weighted_out.push_back(weighted);
  }
  return e;
}

}  // namespace dynid::residual::detail
