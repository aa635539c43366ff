#include "dynid/report/residual_report.hpp"

#include <cmath>
#include <map>

#include <fmt/format.h>

#include "dynid/residual/road_profile.hpp"

namespace dynid::report {
namespace {

std::string number(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : "-"; }
std::string percent(double v) { return std::isfinite(v) ? fmt::format("{:.2f}", v) : "-"; }
// A road profile's knot parameter: <profile effect>[@group]@<distance>m. Other names with '@'
// (a dictionary term's coefficient in one equation group) are listed.
bool is_profile_knot(const residual::ParameterChange& p) {
  return residual::is_road_profile_effect(p.name.substr(0, p.name.find('@')));
}

}  // namespace

std::string format_screen_text(const residual::ScreenResult& screen, std::size_t top) {
  std::string out = fmt::format("model {} (effects: {})\n", screen.fit.model,
                                screen.fit.effects.empty() ? "none" : fmt::format("{}", fmt::join(screen.fit.effects, ", ")));
  for (const residual::GroupFit& g : screen.fit.groups)
    out += fmt::format("group {}: {} rows, residual RMS {} (held out {}), relative norm {:.4f}\n", g.group, g.rows,
                       number(g.rms_in_sample), number(g.rms_held_out), g.relative_norm_in_sample);
  out += fmt::format("{:<34} {:<12} {:>10} {:>11} {:>10} {:>9} {:>6}  {}\n", "candidate", "kind", "in-sample%",
                     "held-out%", "HAC Wald", "p", "folds", "significant");
  std::size_t shown = 0;
  std::map<std::string, std::size_t> untested;
  for (const residual::CandidateScore& c : screen.candidates) {
    if (!c.evaluated) {
      ++untested[c.note];
      continue;
    }
    if (shown++ >= top) continue;
    out += fmt::format("{:<34} {:<12} {:>10.2f} {:>11.2f} {:>10.3g} {:>9.2g} {:>3}/{:<2}  {}{}\n", c.effect,
                       residual::kind_name(c.kind), 100.0 * c.in_sample_drop, 100.0 * c.held_out_drop,
                       c.wald_statistic, c.p_value, c.folds_improved, c.folds,
                       c.significant ? "yes" : (c.testable ? "no" : "not identifiable"),
                       c.rows_outside > 0 ? fmt::format(" (on the declared rows; {} rows of its own left out)",
                                                        c.rows_outside)
                                          : "");
  }
  out += fmt::format("each candidate tested at level {:.2g} ({} candidates, family error rate {:.2g})\n",
                     screen.level, screen.tests, screen.level * screen.tests);
  if (shown > top) out += fmt::format("... and {} more tested\n", shown - top);
  for (const auto& [reason, count] : untested) out += fmt::format("not tested ({}): {}\n", count, reason);
  return out + "verdict: " + screen.verdict() + "\n";
}

std::string format_comparison_text(const residual::EffectComparison& c) {
  std::string out = fmt::format("add {} to {}\n", c.effect, c.before.model);
  out += fmt::format("{:<30} {:>14} {:>12} {:>9} | {:>14} {:>12} {:>9}\n", "parameter", "before", "std", "err %",
                     "after", "std", "err %");
  std::size_t knots = 0;
  for (const residual::ParameterChange& p : c.parameters) {
    if (is_profile_knot(p) && !p.truth) {
      ++knots;
      continue;
    }
    out += fmt::format("{:<30} {:>14} {:>12} {:>9} | {:>14} {:>12} {:>9}\n", p.name, number(p.before),
                       number(p.std_before), percent(p.error_before_percent()), number(p.after),
                       number(p.std_after), percent(p.error_after_percent()));
  }
  if (knots > 0)
    out += fmt::format("({} road-profile knot parameters, every {:.0f} m, not listed)\n", knots,
                       c.after.profile_knots_m.size() > 1 ? c.after.profile_knots_m[1] : 0.0);
  for (std::size_t g = 0; g < c.before.groups.size() && g < c.after.groups.size(); ++g) {
    const residual::GroupFit& b = c.before.groups[g];
    const residual::GroupFit& a = c.after.groups[g];
    out += fmt::format("group {}: residual RMS in sample {} -> {}, held out {} -> {}; relative norm {:.4f} -> {:.4f} "
                       "(held out {:.4f} -> {:.4f})\n",
                       b.group, number(b.rms_in_sample), number(a.rms_in_sample), number(b.rms_held_out),
                       number(a.rms_held_out), b.relative_norm_in_sample, a.relative_norm_in_sample,
                       b.relative_norm_held_out, a.relative_norm_held_out);
  }
  return out + fmt::format("weighted residual RMS: {:.1f} % lower in sample, {:.1f} % lower held out\n",
                           100.0 * c.in_sample_drop(), 100.0 * c.held_out_drop());
}

}  // namespace dynid::report
