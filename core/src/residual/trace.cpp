#include "dynid/residual/trace.hpp"

#include <cmath>
#include <cstdio>

#include "dynid/cancellation.hpp"
#include "dynid/error.hpp"

namespace dynid::residual {
namespace {

std::string four_digits(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Why adding the accepted candidate is refused, or empty when it is not.
std::string refusal(const EffectComparison& c) {
  if (!(c.held_out_drop() > 0.0))
    return c.effect + " refused: with it the held-out residual is not lower (" +
           std::to_string(100.0 * -c.held_out_drop()) + " %)";
  for (std::size_t i = 0; i < c.parameters.size() && i < c.after.parameters.size(); ++i) {
    const ParameterChange& p = c.parameters[i];
    const model::ParameterInfo& info = c.after.parameters[i];
    if (const std::string why = out_of_bounds(info, p.after, p.std_after); !why.empty())
      return c.effect + " refused: it takes " + why;
    // A value the model held within its bounds and the candidate takes out of them, whatever its
    // std: the candidate absorbs that parameter (a loop must not end on an impossible value).
    if (std::isfinite(p.before) && info.within_bounds(p.before) && std::isfinite(p.after) && !info.within_bounds(p.after))
      return c.effect + " refused: it takes " + info.name + " from " + four_digits(p.before) + " to " +
             four_digits(p.after) + " " + info.unit + ", outside its physical bounds (" + info.bounds_text() + ")";
  }
  return {};
}

// Hausman's comparison of the declared parameters before and after `c` (trace.hpp): the one
// that moved most in std of the difference, and the bound at 1 % over the declared parameters.
struct LargestMove {
  const ParameterChange* parameter = nullptr;
  double moved = 0.0;  ///< std of the difference
  double bound = 0.0;
  std::size_t declared = 0;
  bool beyond() const { return parameter != nullptr && moved > bound; }
  std::string text() const {
    return "it takes " + parameter->name + " from " + four_digits(parameter->before) + " to " +
           four_digits(parameter->after) + " " + parameter->unit + ", " + four_digits(moved) +
           " std of the difference (Hausman, at most " + four_digits(bound) + " at 1 % over " +
           std::to_string(declared) + " parameters)";
  }
};

// `sharpens`: the candidate is a better sensor, efficient under the hypothesis (hausman_distance).
LargestMove largest_move(const EffectComparison& c, bool sharpens) {
  LargestMove out;
  for (const ParameterChange& p : c.parameters)
    out.declared += std::isfinite(p.before) && std::isfinite(p.after) ? 1 : 0;
  if (out.declared == 0) return out;
  out.bound = hausman_bound(out.declared);
  for (const ParameterChange& p : c.parameters) {
    const double moved = hausman_distance(p, sharpens);
    if (moved > out.moved) out.parameter = &p, out.moved = moved;
  }
  return out;
}

}  // namespace

std::vector<std::string> Trace::added() const {
  std::vector<std::string> out;
  for (const TraceRound& r : rounds)
    if (r.added) out.push_back(r.added->effect);
  return out;
}

std::string partial_refusal(const EffectComparison& c) {
  const LargestMove m = largest_move(c, false);
  if (!m.beyond()) return {};
  return c.effect + " refused: it explains a part of the residual only, and " + m.text() +
         ": with the model still above its floor, nothing says the moved values are nearer the "
         "car's";
}

std::string better_sensor_refusal(const EffectComparison& c) {
  const LargestMove m = largest_move(c, true);
  if (!m.beyond()) return {};
  return c.effect +
         " refused: as a better sensor of a declared signal (at the declared floor) it should "
         "sharpen the parameters, not move them, but " +
         m.text() + ": it differs from that signal systematically, not only in noise";
}

Trace trace(const model::Model& model, const std::vector<std::string>& declared,
            const ingest::RecordedRun& run, const TraceOptions& options) {
  if (options.max_rounds < 0) throw InputError("trace: max_rounds " + std::to_string(options.max_rounds) + " < 0");
  const std::vector<ingest::PreprocessedSegment> segments = ingest::preprocess_offline(run);
  const double rate = run.announcement.sample_rate_hz;
  const int odmf = run.announcement.preprocessing.odmf;
  Trace t;
  t.model = model.name();
  t.declared = declared;
  std::vector<std::string> effects = declared;
  FloorCache cache(run, segments);
  for (int round = 0;; ++round) {
    cancellation_point();
    TraceRound r{effects, diagnose(model, effects, run, segments, options.diagnosis, cache),
                 std::nullopt};
    const Verdict verdict = r.diagnosis.verdict;
    // A partial explanation is added like a full one (what it leaves may be a second effect),
    // unless it moves the declared physics (partial_refusal).
    if (!r.diagnosis.accepted) {
      t.stopped = std::string(verdict_name(verdict)) + " after " + std::to_string(round) + " added effect" +
                  (round == 1 ? "" : "s");
      t.rounds.push_back(std::move(r));
      return t;
    }
    if (round == options.max_rounds) {
      t.stopped = "stopped at the limit of " + std::to_string(options.max_rounds) + " added effects; " +
                  r.diagnosis.accepted->effect + " would be next";
      t.rounds.push_back(std::move(r));
      return t;
    }
    EffectComparison c = compare_effect(model, effects, r.diagnosis.accepted->effect, segments, rate, odmf,
                                        options.diagnosis.screen.fit, options.reference);
    std::string why = refusal(c);
    if (why.empty() && r.diagnosis.masked) why = better_sensor_refusal(c);
    if (why.empty() && r.diagnosis.partial && !r.diagnosis.better_sensor &&
        r.diagnosis.accepted->kind == CandidateKind::kDictionary)
      why = partial_refusal(c);
    if (!why.empty()) {
      t.stopped = why + (r.diagnosis.implausible.empty() ? "" : "; the model as it stands is implausible on this run");
      t.rounds.push_back(std::move(r));
      return t;
    }
    effects.push_back(c.effect);
    r.added = std::move(c);
    t.rounds.push_back(std::move(r));
  }
}

}  // namespace dynid::residual
