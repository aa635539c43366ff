#include "scoring.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "car/clean_run.hpp"
#include "car/declared_fit.hpp"
#include "car/parameters.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/report/residual_report.hpp"
#include "dynid/residual/consistency.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::benchtrace {
namespace {

std::string fmt(const char* format, double a, double b = 0.0, double c = 0.0) {
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, format, a, b, c);
  return buffer;
}

std::string signature_text(const residual::Signature& s) {
  std::string out;
  for (std::size_t i = 0; i < s.correlations.size() && i < 2; ++i) {
    const residual::CorrelationFinding& c = s.correlations[i];
    out += (out.empty() ? "" : "; ") + c.channel + fmt(" at %+.2f s (r %.2f)", c.lag_s, c.correlation);
  }
  out += (out.empty() ? "" : "; ") + fmt("most in %.0f-%.0f s, peak %.2f Hz", s.span_start_s, s.span_end_s, s.peak_frequency_hz);
  return out;
}

// A step's right answer also locates it: its 95 % set holds the time the simulated car changed.
bool holds_change(const ModelRun& m, double change_time_s) {
  return m.first_located_from_s <= change_time_s && change_time_s <= m.first_located_to_s;
}

// The loop on one model, with its guarantees checked.
ModelRun trace_model(const RunSetup& setup, const std::string& name, const ingest::RecordedRun& run,
                     const std::vector<ingest::PreprocessedSegment>& segments, const std::map<std::string, double>& truth) {
  const car::VehicleProfile& profile = *setup.profile;
  const ingest::ModelSpec spec = benchcar::model_spec(profile, name);
  const auto model = model::make_model(spec.model, spec.constants);
  residual::TraceOptions options;
  options.reference = truth;
  const residual::Trace t = residual::trace(*model, spec.effects, run, options);
  ModelRun m;
  m.model = name;
  const residual::Diagnosis& first = t.rounds.front().diagnosis;
  m.first_verdict = residual::verdict_name(first.verdict);
  if (first.accepted) {
    m.first_effect = first.accepted->effect;
    m.first_partial = first.partial.has_value();
    m.first_finding = first.accepted->finding;
    m.first_located_from_s = first.accepted->located_from_s;
    m.first_located_to_s = first.accepted->located_to_s;
  }
  for (const residual::GroupFloor& g : first.floor.groups)
    if (g.ratio / g.upper_ratio > m.first_ratio / std::max(m.first_upper, 1e-300) || m.first_upper == 0.0) {
      m.first_ratio = g.ratio;
      m.first_upper = g.upper_ratio;
    }
  for (const residual::Inseparable& i : first.inseparable) m.first_inseparable.push_back(i.effect);
  if (t.rounds.size() > 1)
    for (const residual::GroupFloor& g : t.rounds[1].diagnosis.floor.groups)
      if (g.rows > 0 && g.ratio / g.upper_ratio > m.second_ratio / std::max(m.second_upper, 1e-300)) {
        m.second_ratio = g.ratio;
        m.second_upper = g.upper_ratio;
      }
  if (first.verdict == residual::Verdict::kStructureLeft) m.signature = signature_text(first.signature);
  if (setup.verbose) {
    m.report = report::format_diagnosis_text(first, 8);
    for (const residual::ChannelNoise& c : first.floor.channels)
      m.report += c.channel + ": sigma " + std::to_string(c.sigma) + ", relative variance of sigma^2 " +
                  std::to_string(c.level_relative_variance) + "\n";
    for (const residual::GroupFloor& g : first.floor.groups)
      m.report += g.group + fmt(": floor relative std %.3g, log-ratio std %.3g", g.floor_relative_std, g.log_ratio_std) +
                  fmt(", effective rows %.0f\n", g.effective_rows);
  }
  m.added = t.added();
  m.stopped = t.stopped;
  // Guarantees: the model as the loop leaves it, refitted on the declared fit's group weights.
  const residual::ModelFit& start = first.screen.fit;
  residual::FitOptions fit_options;
  fit_options.series = false;
  for (const ls::GroupStatistics& g : start.group_statistics) fit_options.group_weights.push_back(g.weight);
  std::vector<std::string> effects = spec.effects;
  effects.insert(effects.end(), m.added.begin(), m.added.end());
  const double rate = run.announcement.sample_rate_hz;
  const int odmf = run.announcement.preprocessing.odmf;
  const residual::ModelFit end =
      m.added.empty() ? start : residual::fit_model(*model, effects, segments, rate, odmf, fit_options);
  m.held_out_start = start.weighted_rms_held_out;
  m.held_out_end = end.weighted_rms_held_out;
  m.held_out_ok = !(m.held_out_end > m.held_out_start * (1.0 + 1e-9));
  for (std::size_t i = 0; i < start.parameters.size(); ++i) {
    m.declared_parameters[start.parameters[i].name] = start.estimate.value(static_cast<Eigen::Index>(i));
    m.declared_std[start.parameters[i].name] = start.estimate.standard_deviation(static_cast<Eigen::Index>(i));
  }
  for (std::size_t i = 0; i < end.parameters.size(); ++i) {
    const double v = end.estimate.value(static_cast<Eigen::Index>(i));
    m.final_parameters[end.parameters[i].name] = v;
    m.final_std[end.parameters[i].name] = end.estimate.standard_deviation(static_cast<Eigen::Index>(i));
    if (!std::isnan(v) && !end.parameters[i].within_bounds(v)) {
      m.bounds_ok = false;
      m.bounds_violations += (m.bounds_violations.empty() ? "" : ", ") + end.parameters[i].name + fmt(" = %.4g", v);
    }
  }
  return m;
}

// The product's consistency check (residual/consistency.hpp) over the run's models as declared:
// shared parameters compared within their HAC std, on the values `dynid consistency` weighs.
// Flagged: a significant disagreement.
void cross_check(const RunSetup& setup, const std::vector<std::string>& models,
                 const std::vector<ingest::PreprocessedSegment>& segments, const ingest::RecordedRun& run,
                 RunResult& r) {
  if (models.size() < 2) return;
  std::vector<residual::ModelParameters> fits;
  for (const std::string& name : models)
    fits.push_back(benchcar::declared_compared(*setup.profile, name, run, segments));
  const residual::Consistency c = residual::check_consistency(fits, {});
  r.cross_checked = !c.comparisons.empty();
  r.cross_flagged = !c.consistent();
  r.cross_one_ratio = !c.scales.empty() && c.scales.front().one_ratio;
  r.cross_text = c.statement();
}

}  // namespace

const char* outcome_name(Outcome o) {
  switch (o) {
    case Outcome::kRight: return "right";
    case Outcome::kProxy: return "proxy";
    case Outcome::kStructureRight: return "structure-left (right)";
    case Outcome::kInseparable: return "reported inseparable";
    case Outcome::kWrong: return "wrong";
    case Outcome::kMissed: return "missed (adequate)";
    case Outcome::kStructureMissed: return "missed (structure left)";
    case Outcome::kError: return "error";
  }
  return "?";
}

bool is_right(Outcome o) {
  return o == Outcome::kRight || o == Outcome::kProxy || o == Outcome::kStructureRight || o == Outcome::kInseparable;
}

RunResult run_family(const RunSetup& setup, const Family& family, std::uint64_t seed) {
  const auto t0 = std::chrono::steady_clock::now();
  RunResult r;
  r.family = family.name;
  r.seed = seed;
  try {
    std::mt19937_64 rng(benchcar::run_seed(family.name, seed));
    const Draw draw = family.draw(rng);
    r.drawn = draw.text;
    const benchcar::CarParameters car;
    const benchcar::Truth truth = benchcar::simulate(family.manoeuvre, car, draw.perturbation, seed);
    const std::string run_name = family.name + "-" + std::to_string(seed);
    const benchcar::ProductRun product = benchcar::through_product(
        *setup.profile, truth, draw.perturbation, {setup.noise_scale, benchcar::run_seed(run_name, seed)}, run_name, setup.work_dir);
    const auto segments = ingest::preprocess_offline(product.recorded);
    for (const std::string& m : family.models)
      r.models.push_back(trace_model(setup, m, product.recorded, segments, truth.parameters));
    cross_check(setup, family.models, segments, product.recorded, r);
    const ModelRun& m = r.models.front();
    for (const std::string& e : m.added) r.right_later = r.right_later || family.right(e, draw) || family.proxy(e, draw);
    if (family.expect == Expect::kCrossModel) {
      // Right: the consistency check finds the two models off by one common ratio (a scale).
      r.outcome = r.cross_flagged && r.cross_one_ratio ? Outcome::kRight
                                                       : (r.cross_flagged ? Outcome::kWrong : Outcome::kMissed);
    } else if (m.first_verdict == "adequate") {
      // The "cannot be separated on this run": the right effect, named as one this run
      // cannot rule out although it would bias the declared parameters.
      const bool reported = std::any_of(m.first_inseparable.begin(), m.first_inseparable.end(),
                                        [&](const std::string& e) { return family.right(e, draw); });
      r.outcome = reported && family.inseparable_is_right ? Outcome::kInseparable : Outcome::kMissed;
    } else if (m.first_verdict == "structure left" && family.expect == Expect::kStructureLeft) {
      r.outcome = Outcome::kStructureRight;
    } else if (m.first_verdict == "structure left" && m.first_effect.empty()) {
      r.outcome = Outcome::kStructureMissed;
    } else if (family.right(m.first_effect, draw) && (family.kind != "step" || holds_change(m, truth.change_time_s))) {
      r.outcome = Outcome::kRight;
    } else if (family.proxy(m.first_effect, draw)) {
      r.outcome = Outcome::kProxy;
    } else {
      r.outcome = Outcome::kWrong;
    }
  } catch (const std::exception& e) {
    r.outcome = Outcome::kError;
    r.error = e.what();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

RunResult run_clean(const RunSetup& setup, benchcar::Manoeuvre manoeuvre, const std::vector<std::string>& models,
                    std::uint64_t seed) {
  const auto t0 = std::chrono::steady_clock::now();
  RunResult r;
  r.family = std::string("clean-") + benchcar::manoeuvre_name(manoeuvre);
  r.seed = seed;
  try {
    const benchcar::CleanRun run = benchcar::clean_run(*setup.profile, manoeuvre, seed, setup.noise_scale, setup.work_dir);
    bool alarm = false;
    for (const std::string& m : models) {
      r.models.push_back(trace_model(setup, m, run.product.recorded, run.segments, run.truth.parameters));
      alarm = alarm || r.models.back().first_verdict != "adequate";
    }
    cross_check(setup, models, run.segments, run.product.recorded, r);
    r.outcome = alarm ? Outcome::kWrong : Outcome::kRight;
  } catch (const std::exception& e) {
    r.outcome = Outcome::kError;
    r.error = e.what();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace dynid::benchtrace
