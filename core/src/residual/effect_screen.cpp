#include "dynid/residual/effect_screen.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include <boost/math/distributions/normal.hpp>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"
#include "dynid/residual/road_profile.hpp"
#include "dynid/residual/sensor_offset.hpp"
#include "dynid/residual/signal_delay.hpp"
#include "dynid/residual/varying_parameter.hpp"
#include "change_point.hpp"
#include "folded_rows.hpp"
#include "hac_wald.hpp"

namespace dynid::residual {
namespace {

// Relative drops closer than this are ties (the same column under two names).
constexpr double kTie = 1e-6;
// The power at which CandidateScore::detectable is stated (the usual design figure).
constexpr double kPower = 0.8;

struct Candidate {
  std::string effect;
  std::string description;
  CandidateKind kind;
};

bool contains(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

// The channels of the model's physics: its own and its candidate effects' (d_<x> read as x:
// the dictionary's own d/dt covers it).
std::vector<std::string> physics_channels(const model::Model& m) {
  std::vector<std::string> out;
  auto add = [&](std::string name) {
    if (name.rfind("d_", 0) == 0) name = name.substr(2);
    if (!contains(out, name)) out.push_back(name);
  };
  for (const model::ChannelNeed& c : m.channels()) add(c.name);
  for (const model::Effect& e : m.candidate_effects())
    for (const std::string& c : e.channels) add(c);
  return out;
}

// Dictionary terms over the run's announced channels (not the derived d_ ones), except over the
// model's measured side, and, unless all_channels, only over the model's physics channels.
std::vector<Candidate> dictionary_candidates(const model::Model& m,
                                             const std::vector<ingest::PreprocessedSegment>& run,
                                             bool all_channels) {
  const std::vector<std::string> physics = physics_channels(m);
  model::ChannelSet announced(run.front().channels.sample_period(), 0);
  for (const std::string& name : run.front().channels.names())
    if (name.rfind("d_", 0) != 0 && !contains(m.measured_side(), name) &&
        (all_channels || contains(physics, name)))
      announced.add(name, run.front().channels.unit(name), Eigen::VectorXd());
  std::vector<Candidate> out;
  for (const model::Effect& e : model::dictionary_effects(announced))
    out.push_back({e.name, e.description, CandidateKind::kDictionary});
  return out;
}

// The channels a parameter may depend on (depends:<p>~<ch>): the model's physics channels that
// the run has, not its measured side (a parameter times a sensor of the very force it explains
// would fit and mean nothing, as for the dictionary).
std::vector<std::string> dependence_channels(const model::Model& m, const std::vector<ingest::PreprocessedSegment>& run) {
  std::vector<std::string> out;
  for (const std::string& c : physics_channels(m))
    if (run.front().channels.has(c) && !contains(m.measured_side(), c)) out.push_back(c);
  return out;
}

// The model's physics channels that the run has (a cumulative quantity reads those only).
std::vector<std::string> run_physics_channels(const model::Model& m, const std::vector<ingest::PreprocessedSegment>& run) {
  std::vector<std::string> out;
  for (const std::string& c : physics_channels(m))
    if (run.front().channels.has(c)) out.push_back(c);
  return out;
}

std::vector<Candidate> candidates_of(const model::Model& m, const std::vector<std::string>& declared,
                                     const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                                     const ScreenOptions& options) {
  std::vector<Candidate> all;
  for (const model::Effect& e : m.candidate_effects())
    all.push_back({e.name, e.description, CandidateKind::kPhysics});
  if (options.varying_parameters) {
    const double t_first = static_cast<double>(run.front().first) / sample_rate_hz;
    const double t_last =
        static_cast<double>(run.back().first + run.back().channels.samples() - 1) / sample_rate_hz;
    const bool dependences = options.dependences || !options.only.empty();
    for (const std::string& name :
         varying_candidates(m, t_first, t_last, options.fit.cross_validation.block_seconds,
                            dependences ? dependence_channels(m, run) : std::vector<std::string>{},
                            cumulative_quantities(run_physics_channels(m, run))))
      all.push_back({name, varying_parameter_info(parse_varying_effect(name, m), m).description,
                     CandidateKind::kVarying});
  }
  if (options.road_profile && run.front().channels.has("vx"))
    all.push_back({road_profile_effect_name(m),
                   "an unmeasured road property (grade, bank) piecewise linear in the distance "
                   "travelled, knots every " +
                       std::to_string(static_cast<int>(options.fit.profile_knot_spacing_m)) + " m",
                   CandidateKind::kRoadProfile});
  if (options.dictionary)
    for (Candidate& c : dictionary_candidates(m, run, options.dictionary_all_channels))
      all.push_back(std::move(c));
  std::vector<Candidate> out;
  for (Candidate& c : all) {
    if (contains(declared, c.effect)) continue;
    if (!options.only.empty() && !contains(options.only, c.effect)) continue;
    out.push_back(std::move(c));
  }
  return out;
}

// Weighted sums of squares of the model without the candidate (every column but the last
// effect's: a declared road profile's columns come after it) and with it, on the rows both
// keep, under the declared model's fixed group weights; and the HAC Wald test of its columns.
CandidateScore score(const Candidate& c, const detail::FoldedRows& rows, const std::vector<double>& weights,
                     int odmf) {
  std::vector<Eigen::Index> base_columns;
  for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(rows.parameters.size()); ++j)
    if (j < rows.last_effect_first || j >= rows.last_effect_end) base_columns.push_back(j);
  const detail::Evaluation before = detail::evaluate(rows, base_columns, weights);
  const detail::Evaluation after = detail::evaluate(rows, {}, weights);
  CandidateScore s;
  s.effect = c.effect;
  s.description = c.description;
  s.kind = c.kind;
  s.columns = static_cast<std::size_t>(rows.last_effect_end - rows.last_effect_first);
  s.rows = after.total_rows();
  s.rows_outside = rows.rows_outside;
  s.evaluated = true;
  const double ss_before = before.weighted_in();
  const double ss_after = after.weighted_in();
  s.in_sample_drop = ss_before > 0.0 ? 1.0 - std::sqrt(ss_after / ss_before) : 0.0;
  const auto n = static_cast<double>(s.rows);
  s.held_out_rms_before = std::sqrt(before.weighted_out() / n);
  s.held_out_rms_after = std::sqrt(after.weighted_out() / n);
  s.held_out_drop = s.held_out_rms_before > 0.0 ? 1.0 - s.held_out_rms_after / s.held_out_rms_before : 0.0;
  for (std::size_t k = 0; k < after.fold_weighted_out.size(); ++k) {
    const double a = after.fold_weighted_out[k];
    const double b = before.fold_weighted_out[k];
    const bool predicted = !std::isnan(a) && !std::isnan(b) && a > 0.0 && b > 0.0;
    s.fold_log_ratio.push_back(predicted ? std::log(a / b) : std::numeric_limits<double>::quiet_NaN());
    if (!predicted) continue;
    ++s.folds;
    if (a < b) ++s.folds_improved;
  }
  const detail::WaldTest wald = detail::hac_wald_test(rows, after.all.value, after.estimator_weights,
                                                      rows.last_effect_first, rows.last_effect_end, odmf);
  s.testable = wald.testable;
  s.wald_statistic = wald.statistic;
  s.p_value = wald.p_value;
  s.hac_lags = wald.bandwidth;
  if (s.columns == 1) {
    s.coefficient = after.all.value(rows.last_effect_first);
    s.coefficient_std = wald.first_std;
    s.coefficient_textbook_std = after.all.standard_deviation(rows.last_effect_first);
    s.coefficient_unit = rows.parameters[static_cast<std::size_t>(rows.last_effect_first)].unit;
    const Eigen::VectorXd alias =
        detail::regress_column(rows, rows.last_effect_first, base_columns, after.estimator_weights);
    s.alias.assign(alias.data(), alias.data() + alias.size());
  }
  return s;
}

// The channels whose delay the screen tests: the model's own that the run has (d_x read as x: a
// derivative moves with its channel), not its measured side.
std::vector<std::string> delay_channels(const model::Model& m, const std::vector<ingest::PreprocessedSegment>& run,
                                        const std::vector<std::string>& declared) {
  std::vector<std::string> out;
  for (const model::ChannelNeed& c : m.channels()) {
    const std::string name = c.name.rfind("d_", 0) == 0 ? c.name.substr(2) : c.name;
    if (!run.front().channels.has(name) || contains(m.measured_side(), name)) continue;
    const bool already = std::any_of(declared.begin(), declared.end(), [&](const std::string& e) {
      return is_delay_effect(e) && e.rfind("delay:" + name + "@", 0) == 0;
    });
    if (!already && !contains(out, name)) out.push_back(name);
  }
  return out;
}

// A residual at a grid index (NaN when that row is not there: the row is left out).
double at_grid(const std::vector<std::pair<Eigen::Index, double>>& r, Eigen::Index grid) {
  const auto it = std::lower_bound(r.begin(), r.end(), std::make_pair(grid, -std::numeric_limits<double>::infinity()));
  return it != r.end() && it->first == grid ? it->second : std::numeric_limits<double>::quiet_NaN();
}

struct SignalContext {
  const model::Model& model;
  const std::vector<std::string>& declared;
  const std::vector<ingest::PreprocessedSegment>& run;
  double rate;
  int odmf;
  const FitOptions& fit;
  const detail::RowSelection& rows;
  const std::vector<double>& weights;
};

std::vector<std::string> with_delay(const std::vector<std::string>& declared, const std::string& channel,
                                    Eigen::Index samples, double rate) {
  std::vector<std::string> out = declared;
  out.push_back(delay_effect_name(channel, samples, rate));
  return out;
}

// The score test of a delay of `channel` at `center` samples: the column -d r / d L (per sample
// of delay) at the solution x0, from the rows built one sample later and one earlier. At zero it
// tests "no delay"; at the delay found, its coefficient's standard deviation is the delay's
// (Gauss-Newton).
CandidateScore score_delay(const SignalContext& in, const std::string& channel, const Eigen::VectorXd& x0,
                           Eigen::Index center = 0) {
  const detail::FoldedRows base = detail::fold_rows(
      in.model, center == 0 ? in.declared : with_delay(in.declared, channel, center, in.rate), in.run, in.rate,
      in.odmf, in.fit, true, &in.rows);
  // Delays of +-1 sample, by name at this rate (1 sample = 1000 / rate ms, rounded back exactly).
  const auto residuals = [&](Eigen::Index samples) {
    return detail::residuals_at(detail::fold_rows(in.model, with_delay(in.declared, channel, samples, in.rate), in.run,
                                                  in.rate, in.odmf, in.fit, true, &in.rows),
                                x0);
  };
  const detail::GridResiduals late = residuals(center + 1);
  const detail::GridResiduals early = residuals(center - 1);
  std::vector<std::vector<double>> column(base.groups.size());
  for (std::size_t g = 0; g < base.groups.size(); ++g)
    for (const Eigen::Index grid : base.collected.grid_index[g])
      column[g].push_back(0.5 * (at_grid(early[g], grid) - at_grid(late[g], grid)));
  const model::ParameterInfo info{channel + "_delay", "samples", "delay of " + channel + " (first order)", std::nullopt};
  const Candidate c{"delay:" + channel, "the " + channel + " signal late or early against the others",
                    CandidateKind::kTiming};
  return score(c, detail::with_extra_column(base, column, info, in.fit.cross_validation), in.weights, in.odmf);
}

// A located delay or offset judged like any other candidate, on the rows built with it: the
// declared model on those rows against the declared model on its own, both under the declared
// weights, per row (the shift drops the few rows whose source leaves their segment). Why: the
// score column is a linearisation at zero delay; it ranked a steering signal 117 ms late at
// -47 % held out where the rows at the delay give -87 % (bench/trace).
void rescore_with(CandidateScore& c, const SignalContext& in, const std::string& effect) {
  const auto evaluated = [&](const std::vector<std::string>& effects) {
    return detail::evaluate(detail::fold_rows(in.model, effects, in.run, in.rate, in.odmf, in.fit, false, &in.rows), {},
                            in.weights);
  };
  const detail::Evaluation before = evaluated(in.declared);
  std::vector<std::string> with = in.declared;
  with.push_back(effect);
  const detail::Evaluation after = evaluated(with);
  const auto nb = static_cast<double>(std::max<std::uint64_t>(before.total_rows(), 1));
  const auto na = static_cast<double>(std::max<std::uint64_t>(after.total_rows(), 1));
  const double in_before = before.weighted_in() / nb;
  c.in_sample_drop = in_before > 0.0 ? 1.0 - std::sqrt(after.weighted_in() / na / in_before) : 0.0;
  c.held_out_rms_before = std::sqrt(before.weighted_out() / nb);
  c.held_out_rms_after = std::sqrt(after.weighted_out() / na);
  c.held_out_drop = c.held_out_rms_before > 0.0 ? 1.0 - c.held_out_rms_after / c.held_out_rms_before : 0.0;
  c.fold_log_ratio.clear();
  c.folds = c.folds_improved = 0;
  for (std::size_t k = 0; k < after.fold_weighted_out.size() && k < before.fold_weighted_out.size(); ++k) {
    const double a = after.fold_weighted_out[k] / na;
    const double b = before.fold_weighted_out[k] / nb;
    const bool predicted = std::isfinite(a) && std::isfinite(b) && a > 0.0 && b > 0.0;
    c.fold_log_ratio.push_back(predicted ? std::log(a / b) : std::numeric_limits<double>::quiet_NaN());
    if (!predicted) continue;
    ++c.folds;
    if (a < b) ++c.folds_improved;
  }
}

// The channels whose offset the screen tests (sensor_offset.hpp): the model's accelerometers
// and rate sensors that the run has, not declared offset already. The measured side is not left
// out, as it is from the dictionary: an offset's column is y's derivative in the channel (the
// mass, for m ay), not y's own values, and it cannot mimic any residual.
std::vector<std::pair<std::string, std::string>> offset_channels(const model::Model& m,
                                                                 const std::vector<ingest::PreprocessedSegment>& run,
                                                                 const std::vector<std::string>& declared) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const model::ChannelNeed& c : m.channels()) {
    if (!is_mounted_sensor(c.name, c.unit) || !run.front().channels.has(c.name)) continue;
    const bool already = std::any_of(declared.begin(), declared.end(), [&](const std::string& e) {
      return is_offset_effect(e) && parse_offset_effect(e).channel == c.name;
    });
    if (!already) out.emplace_back(c.name, c.unit);
  }
  return out;
}

std::vector<std::string> with_offset(const std::vector<std::string>& declared, const std::string& channel, double value) {
  std::vector<std::string> out = declared;
  if (value != 0.0) out.push_back(offset_effect_name(channel, value));
  return out;
}

// The score test of an offset of `channel` around `center` (its unit): the column -d r / d offset
// at the solution x0, by central difference (a model linear in the channel makes it exact); the
// coefficient is the offset beyond `center`.
CandidateScore score_offset(const SignalContext& in, const std::string& channel, const std::string& unit,
                            const Eigen::VectorXd& x0, double center = 0.0) {
  constexpr double kStep = 0.01;  // in the channel's unit: any step is exact for a linear channel
  const detail::FoldedRows base = detail::fold_rows(in.model, with_offset(in.declared, channel, center), in.run,
                                                    in.rate, in.odmf, in.fit, true, &in.rows);
  const auto residuals = [&](double value) {
    return detail::residuals_at(detail::fold_rows(in.model, with_offset(in.declared, channel, value), in.run, in.rate,
                                                  in.odmf, in.fit, true, &in.rows),
                                x0);
  };
  const detail::GridResiduals up = residuals(center + kStep);
  const detail::GridResiduals down = residuals(center - kStep);
  std::vector<std::vector<double>> column(base.groups.size());
  for (std::size_t g = 0; g < base.groups.size(); ++g)
    for (const Eigen::Index grid : base.collected.grid_index[g])
      column[g].push_back((at_grid(down[g], grid) - at_grid(up[g], grid)) / (2.0 * kStep));
  const model::ParameterInfo info{channel + "_offset", unit, "what " + channel + " reads too much", std::nullopt};
  const Candidate c{"offset:" + channel, "the " + channel + " sensor reads an offset (a tilted mount, a bias)",
                    CandidateKind::kSensor};
  return score(c, detail::with_extra_column(base, column, info, in.fit.cross_validation), in.weights, in.odmf);
}

// A significant offset found by two Gauss-Newton steps from zero, judged again on the rows built
// with it, and named with its value (offset:ay@+0.171), its std and the mounting angle it means.
void locate_offset(CandidateScore& c, const SignalContext& in, const std::string& unit) {
  const std::string channel = c.effect.substr(std::string("offset:").size());
  double value = c.coefficient;
  CandidateScore at_value;
  for (int step = 0; step < 2; ++step) {
    const detail::FoldedRows rows = detail::fold_rows(in.model, with_offset(in.declared, channel, value), in.run,
                                                      in.rate, in.odmf, in.fit, false, &in.rows);
    const Eigen::VectorXd x = detail::solution(rows);
    at_value = score_offset(in, channel, unit, x, value);
    if (!at_value.testable || !std::isfinite(at_value.coefficient)) {
      // An offset with no value cannot be added (its name needs one): not a candidate after all.
      c.significant = false;
      c.note = "its offset is not identifiable on this run's rows once sought";
      return;
    }
    value += at_value.coefficient;
  }
  rescore_with(c, in, offset_effect_name(channel, value));
  c.effect = offset_effect_name(channel, value);
  c.coefficient = value;
  c.coefficient_std = at_value.coefficient_std;
  c.finding = offset_finding(channel, unit, value, at_value.coefficient_std);
}

// The delay with the least in-sample weighted residual per row within +-max samples (steps of
// 2 samples, then the neighbours of the best), with the cost of every delay tried.
struct DelayProfile {
  Eigen::Index samples = 0;
  std::map<Eigen::Index, double> cost;  ///< weighted in-sample residual per row
  std::uint64_t rows = 1;
};

DelayProfile profile_delay(const SignalContext& in, const std::string& channel, Eigen::Index max) {
  DelayProfile out;
  const auto consider = [&](Eigen::Index samples) {
    if (out.cost.count(samples) != 0) return;
    const detail::FoldedRows folded = detail::fold_rows(
        in.model, samples == 0 ? in.declared : with_delay(in.declared, channel, samples, in.rate), in.run, in.rate,
        in.odmf, in.fit, false, &in.rows);
    const detail::Evaluation e = detail::evaluate(folded, {}, in.weights);
    out.rows = std::max<std::uint64_t>(e.total_rows(), 1);
    out.cost[samples] = e.weighted_in() / static_cast<double>(out.rows);
  };
  const auto best = [&] {
    return std::min_element(out.cost.begin(), out.cost.end(),
                            [](const auto& a, const auto& b) { return a.second < b.second; })->first;
  };
  for (Eigen::Index l = -max; l <= max; l += 2) consider(l);
  const Eigen::Index coarse = best();
  consider(coarse - 1);
  consider(coarse + 1);
  out.samples = best();
  return out;
}

// The 95 % profile-likelihood interval of the delay: the delays tried whose likelihood ratio
// against the best, n (cost / best - 1), divided by `inflation`, stays within chi-square(1)'s
// 3.84. `inflation` is how much the rows' correlation inflates the variance along the delay
// (the score column's HAC variance over its textbook one at the delay found, at least 1: no row
// counts for more than one): the robust likelihood ratio of a quasi-likelihood. Why not the
// score column's std alone (Gauss-Newton): it ignores that the delay is found on the raw grid
// and that the cost is not quadratic over a few samples; it said 190 +- 1 ms for a speed 200 ms
// late.
struct LocatedDelay {
  Eigen::Index samples = 0;
  Eigen::Index earliest = 0, latest = 0;  ///< the interval, samples
};

LocatedDelay delay_interval(const DelayProfile& p, double inflation) {
  constexpr double kChiSquare1At95 = 3.841;
  LocatedDelay out{p.samples, p.samples, p.samples};
  const double best = p.cost.at(p.samples);
  const double scale = std::isfinite(inflation) ? std::max(inflation, 1.0) : 1.0;
  for (const auto& [samples, c] : p.cost) {
    if (!(best > 0.0) || static_cast<double>(p.rows) * (c / best - 1.0) / scale > kChiSquare1At95) continue;
    out.earliest = std::min(out.earliest, samples);
    out.latest = std::max(out.latest, samples);
  }
  return out;
}

// Why a located delay is no answer, or "": its interval reaches the edge of the search (the
// best delay may lie beyond it, or the cost has no minimum: not a delay). An interval holding 0
// is still offered: the trace then refuses it for its held-out gain, and without a materiality
// rule that refusal is what stops a clean trace from adding immaterial terms one after another.
std::string not_located(const LocatedDelay& d, Eigen::Index max, double rate) {
  const auto ms = [&](Eigen::Index samples) {
    return std::to_string(std::llround(1000.0 * samples / rate));
  };
  if (d.earliest > -max && d.latest < max) return "";
  return "its 95 % interval of delays (" + ms(d.earliest) + " to " + ms(d.latest) +
         " ms) reaches the edge of the search (+-" + ms(max) + " ms): no delay located";
}

std::string seconds_text(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", std::round(t * 1e6) / 1e6);
  return buf;
}

// "mass changes by +250 +- 12 kg at 31.6 s (95 % between 23.00 and 31.60 s); near it: the car
// stood still 28.6-31.2 s": the change point's confidence set (a gap in the rows lies inside
// it whole), then what happened within 2 s of it.
std::string step_finding(const std::string& parameter, const CandidateScore& c, const detail::LocatedStep& step,
                         const SignalContext& in) {
  char text[256];
  std::snprintf(text, sizeof text, "%s changes by %+.4g +- %.2g %s at %s s", parameter.c_str(), c.coefficient,
                c.coefficient_std, c.coefficient_unit.c_str(), seconds_text(step.time_s).c_str());
  std::string out = text;
  std::snprintf(text, sizeof text, " (95 %% between %.2f and %.2f s)", step.earliest_s, step.latest_s);
  out += text;
  const std::string events = detail::events_near(in.run, in.rate, step.earliest_s, step.latest_s, 2.0);
  if (!events.empty()) out += "; near it: " + events;
  return out;
}

// "steer is 120 ms late (95 % interval of its delay: +115 to +125 ms)"; a negative delay is early.
std::string delay_finding(const std::string& channel, Eigen::Index samples, double from_s, double to_s, double rate) {
  char text[200];
  std::snprintf(text, sizeof text, "%s is %.0f ms %s (95 %% interval of its delay: %+.0f to %+.0f ms)", channel.c_str(),
                std::abs(static_cast<double>(samples)) * 1000.0 / rate, samples >= 0 ? "late" : "early", 1000.0 * from_s,
                1000.0 * to_s);
  return text;
}

// The best significant step of each parameter (ranked) moved from its block boundary to the
// change point the rows locate (change_point.hpp), judged again there like any candidate: its
// significance stays the block step's (the test that found it), its figures are the located
// step's. The finding names the time, the size and what happened near it.
void locate_significant_steps(ScreenResult& result, const SignalContext& in) {
  std::vector<std::string> located;
  std::optional<detail::FoldedRows> declared;
  for (CandidateScore& c : result.candidates) {
    if (!c.significant || !c.evaluated || c.effect.rfind("step:", 0) != 0) continue;
    const VaryingParameter v = parse_varying_effect(c.effect, in.model);
    if (contains(located, v.parameter)) continue;
    located.push_back(v.parameter);
    if (!declared) declared = detail::fold_rows(in.model, in.declared, in.run, in.rate, in.odmf, in.fit, true, &in.rows);
    const std::optional<detail::LocatedStep> step = detail::locate_step(*declared, v.column, in.weights);
    if (!step) continue;
    const std::string name = "step:" + v.parameter + "@" + seconds_text(step->time_s) + "s";
    std::vector<std::string> with = in.declared;
    with.push_back(name);
    const Candidate candidate{name, varying_parameter_info(parse_varying_effect(name, in.model), in.model).description,
                              CandidateKind::kVarying};
    CandidateScore again = score(candidate, detail::fold_rows(in.model, with, in.run, in.rate, in.odmf, in.fit, true, &in.rows),
                                 in.weights, in.odmf);
    again.significant = c.significant;
    again.detectable = c.detectable;
    detail::LocatedStep change = *step;
    detail::set_interval(change, std::pow(again.coefficient_std / again.coefficient_textbook_std, 2));
    again.finding = step_finding(v.parameter, again, change, in);
    again.located_from_s = change.earliest_s;
    again.located_to_s = change.latest_s;
    c = std::move(again);
  }
}

// The score `score_it` gives, or, when the candidate cannot be built on this run (a missing
// channel, no row), the candidate untested with the reason.
template <typename ScoreIt>
CandidateScore scored_or_why(const std::string& effect, CandidateKind kind, ScoreIt score_it) {
  try {
    return score_it();
  } catch (const InputError& e) {
    CandidateScore s;
    s.effect = effect;
    s.kind = kind;
    s.note = e.what();
    return s;
  }
}

// Significance once every candidate is scored: the level is shared out among them.
void decide(ScreenResult& result, double family_error_rate) {
  result.tests = static_cast<int>(std::count_if(result.candidates.begin(), result.candidates.end(),
                                                [](const CandidateScore& c) { return c.evaluated; }));
  result.level = result.tests > 0 ? family_error_rate / result.tests : 0.0;
  const double power_z = boost::math::quantile(boost::math::normal(), kPower);
  for (CandidateScore& c : result.candidates) {
    c.significant = c.evaluated && c.testable && c.p_value < result.level && c.held_out_drop > 0.0;
    if (c.testable && c.columns == 1)
      c.detectable = (boost::math::quantile(boost::math::normal(), 1.0 - result.level / 2.0) + power_z) *
                     c.coefficient_std;
  }
}

// Significant first; then by the held-out drop, the
// predictive criterion (a candidate with many columns pays for them there); equal drops (the
// same column under two names: road_grade and dict:x:road_grade) go to the earlier kind.
bool ranks_before(const CandidateScore& a, const CandidateScore& b) {
  if (a.evaluated != b.evaluated) return a.evaluated;
  if (a.significant != b.significant) return a.significant;
  if (std::abs(a.held_out_drop - b.held_out_drop) > kTie * std::max(1.0, std::abs(a.held_out_drop)))
    return a.held_out_drop > b.held_out_drop;
  return static_cast<int>(a.kind) < static_cast<int>(b.kind);
}

// How much worse b's held-out error is than a's (the mean over the folds both predicted of the
// difference of their log ratios), and the standard error of a's held-out error over those
// folds: the one-standard-error rule's yardstick (Hastie, Tibshirani and Friedman, 7.10), the
// spread of the best model's own cross-validation error. Why not the standard error of the
// paired difference: two versions of one column (road_bank and its 3-sample lag) differ by so
// little, so evenly over the folds, that a 0.1 % gap was many of its own errors.
std::pair<double, double> one_error_gap(const CandidateScore& a, const CandidateScore& b) {
  std::vector<double> d, own;
  for (std::size_t k = 0; k < a.fold_log_ratio.size() && k < b.fold_log_ratio.size(); ++k)
    if (std::isfinite(a.fold_log_ratio[k]) && std::isfinite(b.fold_log_ratio[k])) {
      d.push_back(b.fold_log_ratio[k] - a.fold_log_ratio[k]);
      own.push_back(a.fold_log_ratio[k]);
    }
  if (d.size() < 2) return {0.0, std::numeric_limits<double>::infinity()};
  const auto n = static_cast<double>(d.size());
  double mean = 0.0, own_mean = 0.0;
  for (std::size_t k = 0; k < d.size(); ++k) mean += d[k] / n, own_mean += own[k] / n;
  double ss = 0.0;
  for (double v : own) ss += (v - own_mean) * (v - own_mean);
  return {mean, std::sqrt(ss / (n - 1.0) / n)};
}

std::string pvalue(double p) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g", p);
  return buf;
}

std::string percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %%", 100.0 * fraction);
  return buf;
}

}  // namespace

// The one-standard-error rule (see the header): the best significant candidate of the first
// kind that is within one standard error of the best overall moves to the front.
void prefer_simplest_within_one_error(std::vector<CandidateScore>& ranked) {
  if (ranked.empty() || !ranked.front().significant || ranked.front().kind == CandidateKind::kSensor) return;
  const CandidateScore& best = ranked.front();
  for (int kind = static_cast<int>(CandidateKind::kSensor); kind < static_cast<int>(best.kind); ++kind) {
    const auto first = std::find_if(ranked.begin(), ranked.end(), [&](const CandidateScore& c) {
      return c.significant && static_cast<int>(c.kind) == kind;
    });
    if (first == ranked.end()) continue;
    const auto [mean, error] = one_error_gap(best, *first);
    if (mean <= error) {
      std::rotate(ranked.begin(), first, first + 1);
      return;
    }
  }
}

const char* kind_name(CandidateKind kind) {
  switch (kind) {
    case CandidateKind::kPhysics: return "physics";
    case CandidateKind::kVarying: return "varying";
    case CandidateKind::kTiming: return "timing";
    case CandidateKind::kSensor: return "sensor";
    case CandidateKind::kRoadProfile: return "road profile";
    case CandidateKind::kDictionary: return "dictionary";
  }
  return "?";
}

const CandidateScore* ScreenResult::best() const {
  return !candidates.empty() && candidates.front().significant ? &candidates.front() : nullptr;
}

std::string ScreenResult::verdict() const {
  if (const CandidateScore* b = best())
    return b->effect + " (" + kind_name(b->kind) + ") explains the residual of " + fit.model +
           ": held-out RMS " + percent(-b->held_out_drop) + " (in sample " +
           percent(-b->in_sample_drop) + "), HAC Wald p = " + pvalue(b->p_value) + " < " +
           pvalue(level);
  const auto first = std::find_if(candidates.begin(), candidates.end(),
                                  [](const CandidateScore& c) { return c.evaluated; });
  if (first == candidates.end()) return "no candidate effect could be tested on this run";
  return "nothing significant at the family error rate: no candidate's HAC Wald p below " + pvalue(level) +
         " with a held-out gain for " + fit.model + "; the best, " + first->effect + ", held-out RMS " +
         percent(-first->held_out_drop) + ", p = " + pvalue(first->p_value);
}

ScreenResult screen_effects(const model::Model& model, const std::vector<std::string>& declared,
                            const std::vector<ingest::PreprocessedSegment>& run,
                            double sample_rate_hz, int odmf, const ScreenOptions& options) {
  if (run.empty()) throw InputError("residual analysis of " + model.name() + ": the run has no valid segment");
  ScreenResult result;
  result.fit = fit_model(model, declared, run, sample_rate_hz, odmf, options.fit);
  std::vector<double> weights;
  for (const GroupFit& g : result.fit.groups) weights.push_back(g.sigma > 0.0 ? 1.0 / g.sigma : 0.0);
  FitOptions fold_options = options.fit;
  fold_options.series = false;
  const detail::RowSelection declared_rows = detail::kept_rows(model, declared, run, sample_rate_hz, odmf);
  for (const Candidate& c : candidates_of(model, declared, run, sample_rate_hz, options)) {
    std::vector<std::string> with = declared;
    with.push_back(c.effect);
    try {
      const detail::FoldedRows rows =
          detail::fold_rows(model, with, run, sample_rate_hz, odmf, fold_options, true, &declared_rows);
      result.candidates.push_back(score(c, rows, weights, odmf));
    } catch (const InputError& e) {
      CandidateScore s;
      s.effect = c.effect;
      s.description = c.description;
      s.kind = c.kind;
      s.note = e.what();
      result.candidates.push_back(std::move(s));
    }
  }
  const SignalContext delays{model, declared, run, sample_rate_hz, odmf, fold_options, declared_rows, weights};
  if (options.delays && options.only.empty()) {
    const Eigen::VectorXd x0 = detail::base_solution(result.fit.estimate);
    for (const std::string& channel : delay_channels(model, run, declared)) {
      result.candidates.push_back(scored_or_why("delay:" + channel, CandidateKind::kTiming,
                                                [&] { return score_delay(delays, channel, x0); }));
    }
  }
  std::map<std::string, std::string> offset_units;
  if (options.sensor_offsets && options.only.empty()) {
    const Eigen::VectorXd x0 = detail::base_solution(result.fit.estimate);
    for (const auto& [channel, unit] : offset_channels(model, run, declared)) {
      offset_units[channel] = unit;
      result.candidates.push_back(scored_or_why("offset:" + channel, CandidateKind::kSensor,
                                                [&] { return score_offset(delays, channel, unit, x0); }));
    }
  }
  decide(result, options.family_error_rate);
  for (CandidateScore& c : result.candidates)
    if (c.significant && c.kind == CandidateKind::kSensor && c.effect.find('@') == std::string::npos &&
        std::isfinite(c.coefficient))
      locate_offset(c, delays, offset_units.at(c.effect.substr(std::string("offset:").size())));
  // A significant delay is located and offered under its name (delay:steer@80ms), with its
  // profile-likelihood interval.
  for (CandidateScore& c : result.candidates) {
    if (!c.significant || c.effect.rfind("delay:", 0) != 0 || c.effect.find('@') != std::string::npos) continue;
    const std::string channel = c.effect.substr(6);
    const auto max = static_cast<Eigen::Index>(std::llround(options.max_delay_s * sample_rate_hz));
    const DelayProfile profile = profile_delay(delays, channel, max);
    const detail::FoldedRows at_found = detail::fold_rows(model, with_delay(declared, channel, profile.samples, sample_rate_hz),
                                                          run, sample_rate_hz, odmf, fold_options, false, &declared_rows);
    const Eigen::VectorXd x_found = detail::solution(at_found);
    const CandidateScore along = score_delay(delays, channel, x_found, profile.samples);
    const double inflation = std::pow(along.coefficient_std / along.coefficient_textbook_std, 2);
    const LocatedDelay found = delay_interval(profile, inflation);
    if (const std::string why = not_located(found, max, sample_rate_hz); !why.empty()) {
      c.significant = false;  // the first-order column's misfit is no delay the search can name
      c.note = why;
      continue;
    }
    rescore_with(c, delays, delay_effect_name(channel, found.samples, sample_rate_hz));
    c.effect = delay_effect_name(channel, found.samples, sample_rate_hz);
    // The delays are tried on the raw grid: a true delay between two samples rounds to one of
    // them, so the interval reaches half a sample beyond the delays it keeps.
    c.located_from_s = (static_cast<double>(found.earliest) - 0.5) / sample_rate_hz;
    c.located_to_s = (static_cast<double>(found.latest) + 0.5) / sample_rate_hz;
    c.finding = delay_finding(channel, found.samples, c.located_from_s, c.located_to_s, sample_rate_hz);
  }
  std::stable_sort(result.candidates.begin(), result.candidates.end(), ranks_before);
  if (options.varying_parameters) {
    locate_significant_steps(result, delays);
    std::stable_sort(result.candidates.begin(), result.candidates.end(), ranks_before);
  }
  prefer_simplest_within_one_error(result.candidates);
  return result;
}

}  // namespace dynid::residual
