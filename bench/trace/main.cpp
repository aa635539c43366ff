// dynid-bench-trace: the residual loop's benchmark on a second simulated car (issue 15; docs/RESIDUAL.md
// "Benchmark on a second car"). For every effect family and seed: simulate the bench SUV
// (bench/trace/car) with the drawn effect, replay its CAN log through the product's data path with
// bench/trace/benchcar.toml, run residual::trace on the family's models, classify the loop's first
// answer (families.hpp); then clean runs per model for the false-alarm rate; and the loop's
// guarantees on every run. Prints the table and the totals against issue 15's targets; --json
// writes every run. `--smoke` is the ctest check of the harness and the car (smoke.cpp), not a score.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "car/product_path.hpp"
#include "command_line.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/residual/model_fit.hpp"
#include "families.hpp"
#include "scoring.hpp"
#include "smoke.hpp"

namespace {

using namespace dynid;
using namespace dynid::benchtrace;

struct Options {
  int seeds = 5;
  int clean = 20;
  std::vector<std::string> families;
  std::string json;
  double time_limit_s = 900.0;
  std::string profile = DYNID_BENCHCAR_PROFILE;
  bool smoke = false;
  double noise_scale = 1.0;
  bool verbose = false;  ///< print each first diagnosis in full
  std::string probe, probe_family;  ///< --probe FAMILY e1,e2,...
  std::string dump;  ///< --dump MODEL MANOEUVRE [NOISE]: residual rows of a clean run (debugging)
  std::string dump_manoeuvre;
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "%s\nusage: dynid-bench-trace [--seeds N] [--clean N] [--families a,b,...] [--json FILE]\n"
               "                         [--time-limit SECONDS] [--profile TOML] [--verbose] [--smoke]\n",
               why.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bench::CommandLine args(argc, argv, usage);
  while (args.next()) {
    const std::string& a = args.option();
    if (a == "--seeds") o.seeds = static_cast<int>(args.number(1, 1000));
    else if (a == "--clean") o.clean = static_cast<int>(args.number(0, 1000));
    else if (a == "--families") {
      std::stringstream ss(args.value());
      for (std::string f; std::getline(ss, f, ',');) o.families.push_back(f);
    } else if (a == "--json") o.json = args.value();
    else if (a == "--time-limit") o.time_limit_s = args.number(1, 86400);
    else if (a == "--profile") o.profile = args.value();
    else if (a == "--smoke") o.smoke = true;
    else if (a == "--verbose") o.verbose = true;
    else if (a == "--probe") {
      o.probe_family = args.value();
      o.probe = args.value();
    }
    else if (a == "--dump") {
      o.dump = args.value();
      o.dump_manoeuvre = args.value();
    } else if (a == "--noise") o.noise_scale = args.number(0, 10);
    else if (a == "--help" || a == "-h") usage("");
    else usage("unknown option " + a);
  }
  std::set<std::string> known;
  for (const Family& f : families()) known.insert(f.name);
  for (const std::string& f : o.families)
    if (!known.count(f)) usage("unknown family " + f);
  return o;
}

std::string json_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char b[8];
      std::snprintf(b, sizeof b, "\\u%04x", c);
      out += b;
      continue;
    }
    out += c;
  }
  return out;
}

std::string json_run(const RunResult& r) {
  std::ostringstream o;
  o << "{\"family\":\"" << json_escape(r.family) << "\",\"seed\":" << r.seed << ",\"drawn\":\"" << json_escape(r.drawn)
    << "\",\"outcome\":\"" << outcome_name(r.outcome) << "\",\"seconds\":" << r.seconds << ",\"error\":\""
    << json_escape(r.error) << "\",\"right_added_later\":" << (r.right_later ? "true" : "false");
  if (r.cross_checked)
    o << ",\"consistency\":{\"flagged\":" << (r.cross_flagged ? "true" : "false") << ",\"text\":\""
      << json_escape(r.cross_text) << "\"}";
  o << ",\"models\":[";
  for (std::size_t i = 0; i < r.models.size(); ++i) {
    const ModelRun& m = r.models[i];
    o << (i ? "," : "") << "{\"model\":\"" << m.model << "\",\"first_verdict\":\"" << m.first_verdict
      << "\",\"first_effect\":\"" << json_escape(m.first_effect)
      << "\",\"first_partial\":" << (m.first_partial ? "true" : "false") << ",\"finding\":\"" << json_escape(m.first_finding)
      << "\",\"ratio\":" << m.first_ratio << ",\"upper_ratio\":" << m.first_upper
      << ",\"ratio_after_first\":" << m.second_ratio << ",\"upper_ratio_after_first\":" << m.second_upper << ",\"added\":[";
    for (std::size_t k = 0; k < m.added.size(); ++k) o << (k ? "," : "") << "\"" << json_escape(m.added[k]) << "\"";
    o << "],\"stopped\":\"" << json_escape(m.stopped) << "\",\"signature\":\"" << json_escape(m.signature)
      << "\",\"bounds_ok\":" << (m.bounds_ok ? "true" : "false") << ",\"bounds_violations\":\""
      << json_escape(m.bounds_violations) << "\",\"held_out_ok\":" << (m.held_out_ok ? "true" : "false")
      << ",\"held_out_start\":" << m.held_out_start << ",\"held_out_end\":" << m.held_out_end << ",\"parameters\":{";
    std::size_t k = 0;
    for (const auto& [name, v] : m.final_parameters)
      o << (k++ ? "," : "") << "\"" << json_escape(name) << "\":" << (std::isfinite(v) ? std::to_string(v) : "null");
    o << "}}";
  }
  o << "]}";
  return o.str();
}

std::string answer(const RunResult& r) {
  if (r.outcome == Outcome::kError) return "error: " + r.error;
  std::string out;
  for (const ModelRun& m : r.models) {
    if (!out.empty()) out += " + ";
    out += m.first_effect.empty() ? m.first_verdict : m.first_effect + (m.first_partial ? " (part)" : "");
  }
  return out;
}

void print_run(const RunResult& r) {
  std::printf("  %-26s seed %-3llu %-40s -> %-26s %s (%.1f s)\n", r.family.c_str(),
              static_cast<unsigned long long>(r.seed), r.drawn.c_str(), answer(r).c_str(), outcome_name(r.outcome),
              r.seconds);
  for (const ModelRun& m : r.models) {
    std::printf("      %s: ratio %.2f (floor test up to %.2f), added [", m.model.c_str(), m.first_ratio, m.first_upper);
    for (std::size_t k = 0; k < m.added.size(); ++k) std::printf("%s%s", k ? ", " : "", m.added[k].c_str());
    std::printf("], %s", m.stopped.c_str());
    if (m.second_upper > 0.0) std::printf("; after the first: ratio %.2f (up to %.2f)", m.second_ratio, m.second_upper);
    if (!m.first_finding.empty()) std::printf("; %s", m.first_finding.c_str());
    if (!m.signature.empty()) std::printf("; signature: %s", m.signature.c_str());
    if (!m.bounds_ok) std::printf("; OUT OF BOUNDS: %s", m.bounds_violations.c_str());
    if (!m.held_out_ok) std::printf("; HELD-OUT WORSE %.4g -> %.4g", m.held_out_start, m.held_out_end);
    std::printf("\n%s", m.report.c_str());
  }
  if (r.cross_checked) std::printf("      consistency (dynid consistency): %s%s\n", r.cross_text.c_str(), r.cross_flagged ? ", FLAGGED" : "");
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const car::VehicleProfile& profile = benchcar::profile(o.profile);
  RunSetup setup;
  setup.profile = &profile;
  setup.work_dir = std::filesystem::temp_directory_path() / ("dynid-bench-trace-" + std::to_string(::getpid()));
  setup.noise_scale = o.noise_scale;
  setup.verbose = o.verbose;
  if (!o.dump.empty()) {  // debugging aid: the declared fit's residual rows of one model on a clean run
    const auto m = o.dump_manoeuvre == "lateral" ? benchcar::Manoeuvre::kLateral
                   : o.dump_manoeuvre == "launch" ? benchcar::Manoeuvre::kLaunch
                   : o.dump_manoeuvre == "cruise" ? benchcar::Manoeuvre::kCruise : benchcar::Manoeuvre::kLongitudinal;
    const benchcar::Truth truth = benchcar::simulate(m, {}, {}, 7);
    if (o.dump == "truth") {
      for (std::size_t k = 0; k < truth.time.size(); k += 250) {
        std::printf("%.2f", truth.time[k]);
        for (const auto& [name, x] : truth.channels) std::printf(" %s=%.4g", name.c_str(), x[k]);
        std::printf("\n");
      }
      return 0;
    }
    const auto run = benchcar::through_product(profile, truth, {}, {o.noise_scale, 7}, "dump", setup.work_dir);
    const ingest::ModelSpec spec = benchcar::model_spec(profile, o.dump);
    const auto model = model::make_model(spec.model, spec.constants);
    const residual::ModelFit fit = residual::fit_model(*model, spec.effects, ingest::preprocess_offline(run.recorded),
                                                       100.0, 8);
    for (const residual::ResidualSeries& s : fit.series)
      for (std::size_t i = 0; i < s.time_s.size(); ++i)
        std::printf("%s %.3f %.6g %.6g\n", s.group.c_str(), s.time_s[i], s.measured(static_cast<Eigen::Index>(i)),
                    s.residual(static_cast<Eigen::Index>(i)));
    std::filesystem::remove_all(setup.work_dir);
    return 0;
  }
  if (!o.probe.empty()) {  // debugging aid: fits of one family's run (seed 1) with given effects
    for (const Family& f : families())
      if (f.name == o.probe_family) {
        std::mt19937_64 rng(std::hash<std::string>{}(f.name) ^ (1ULL * 0x9e3779b97f4a7c15ULL));
        const Draw draw = f.draw(rng);
        const benchcar::Truth truth = benchcar::simulate(f.manoeuvre, {}, draw.perturbation, 1);
        const auto run = benchcar::through_product(profile, truth, draw.perturbation, {o.noise_scale, 5}, "probe", setup.work_dir);
        const ingest::ModelSpec spec = benchcar::model_spec(profile, f.models.front());
        const auto model = model::make_model(spec.model, spec.constants);
        const auto segments = ingest::preprocess_offline(run.recorded);
        std::printf("%s: %s\n", f.name.c_str(), draw.text.c_str());
        std::stringstream ss(o.probe);
        residual::FitOptions same_scale;  // the declared fit's weights, as compare_effect does
        for (const residual::GroupFit& g : residual::fit_model(*model, spec.effects, segments, 100.0, 8).groups)
          same_scale.group_weights.push_back(g.sigma > 0.0 ? 1.0 / g.sigma : 0.0);
        for (std::string e; std::getline(ss, e, ',');) {
          std::vector<std::string> effects = spec.effects;
          if (e != "none") effects.push_back(e);
          const residual::ModelFit fit = residual::fit_model(*model, effects, segments, 100.0, 8, same_scale);
          std::printf("  %-28s weighted RMS in sample %.4g, held out %.4g;", e.c_str(), fit.weighted_rms_in_sample,
                      fit.weighted_rms_held_out);
          for (const residual::GroupFit& g : fit.groups)
            std::printf(" %s %.4g (held out %.4g)", g.group.c_str(), g.rms_in_sample, g.rms_held_out);
          std::printf("\n");
        }
      }
    std::filesystem::remove_all(setup.work_dir);
    return 0;
  }
  if (o.smoke) {
    const int failures = run_smoke(setup);
    std::filesystem::remove_all(setup.work_dir);
    return failures == 0 ? 0 : 1;
  }
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  std::vector<RunResult> runs;
  bool cut = false;
  std::printf("dynid-bench-trace: %d seeds per family, %d clean runs per manoeuvre, time limit %.0f s\n", o.seeds, o.clean,
              o.time_limit_s);
  for (const Family& f : families()) {
    if (!o.families.empty() && std::find(o.families.begin(), o.families.end(), f.name) == o.families.end()) continue;
    for (int s = 1; s <= o.seeds; ++s) {
      if (elapsed() > o.time_limit_s) {
        cut = true;
        break;
      }
      runs.push_back(run_family(setup, f, static_cast<std::uint64_t>(s)));
      print_run(runs.back());
    }
  }
  // Clean runs: one run per manoeuvre and seed, every model of that manoeuvre traced on it.
  std::map<benchcar::Manoeuvre, std::vector<std::string>> by_manoeuvre;
  for (const CleanCase& c : clean_cases()) by_manoeuvre[c.manoeuvre].push_back(c.model);
  for (const auto& [manoeuvre, models] : by_manoeuvre)
    for (int s = 1; s <= o.clean; ++s) {
      if (elapsed() > o.time_limit_s) {
        cut = true;
        break;
      }
      runs.push_back(run_clean(setup, manoeuvre, models, 1000 + static_cast<std::uint64_t>(s)));
      print_run(runs.back());
    }
  std::filesystem::remove_all(setup.work_dir);

  // The table.
  std::printf("\n| family | kind | right answer | right/n | median outcome | what won (first answer, count) | right added later |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  int families_right = 0, families_scored = 0;
  for (const Family& f : families()) {
    std::vector<const RunResult*> rs;
    for (const RunResult& r : runs)
      if (r.family == f.name) rs.push_back(&r);
    if (rs.empty()) continue;
    int right = 0, later = 0;
    std::map<std::string, int> won;
    std::vector<int> ranks;
    for (const RunResult* r : rs) {
      right += is_right(r->outcome) ? 1 : 0;
      later += !is_right(r->outcome) && r->right_later ? 1 : 0;
      ++won[answer(*r)];
      ranks.push_back(static_cast<int>(r->outcome));
    }
    std::sort(ranks.begin(), ranks.end());
    const Outcome median = static_cast<Outcome>(ranks[(ranks.size() - 1) / 2]);
    const bool family_right = 2 * right > static_cast<int>(rs.size());
    ++families_scored;
    families_right += family_right ? 1 : 0;
    std::vector<std::pair<int, std::string>> order;
    for (const auto& [a, n] : won) order.emplace_back(-n, a);
    std::sort(order.begin(), order.end());
    std::string what;
    for (std::size_t i = 0; i < order.size() && i < 3; ++i)
      what += (i ? "; " : "") + order[i].second + " x" + std::to_string(-order[i].first);
    std::printf("| %s | %s | %s | %d/%zu | %s | %s | %d |\n", f.name.c_str(), f.kind.c_str(), f.right_text.c_str(), right,
                rs.size(), outcome_name(median), what.c_str(), later);
  }
  std::printf("\nFalse alarms on clean runs (any first verdict but adequate), per model:\n");
  std::map<std::string, std::pair<int, int>> alarms;  // model -> (alarms, runs)
  int cross_flags = 0, cross_runs = 0;
  for (const RunResult& r : runs) {
    if (r.family.rfind("clean-", 0) != 0) continue;
    if (r.cross_checked) {
      ++cross_runs;
      cross_flags += r.cross_flagged ? 1 : 0;
    }
    for (const ModelRun& m : r.models) {
      auto& [a, n] = alarms[m.model];
      ++n;
      if (m.first_verdict != "adequate") ++a;
    }
  }
  bool alarms_ok = true;
  for (const auto& [model, an] : alarms) {
    std::printf("  %-22s %d / %d%s\n", model.c_str(), an.first, an.second, 20 * an.first <= an.second ? "" : "  (above 1 in 20)");
    alarms_ok = alarms_ok && 20 * an.first <= an.second;
  }
  int bounds_bad = 0, held_bad = 0, traces = 0, errors = 0;
  for (const RunResult& r : runs) {
    errors += r.outcome == Outcome::kError ? 1 : 0;
    for (const ModelRun& m : r.models) {
      ++traces;
      bounds_bad += m.bounds_ok ? 0 : 1;
      held_bad += m.held_out_ok ? 0 : 1;
    }
  }
  std::printf("\nGuarantees over %d traces: %d ended with a parameter outside its bounds, %d with a held-out residual "
              "above where it started; %d runs failed with an error.\n",
              traces, bounds_bad, held_bad, errors);
  if (cross_runs > 0) {
    // Per family too: the scale family is where it should fire.
    std::map<std::string, std::pair<int, int>> by_family;
    for (const RunResult& r : runs)
      if (r.cross_checked && r.family.rfind("clean-", 0) != 0) {
        by_family[r.family].second += 1;
        by_family[r.family].first += r.cross_flagged ? 1 : 0;
      }
    std::printf("Consistency check of the product (dynid consistency: the models' shared parameters within their HAC "
                "std, 1 %% family error rate): inconsistent in %d of %d clean runs with two models or more",
                cross_flags, cross_runs);
    for (const auto& [family, fn] : by_family) std::printf("; %d of %d %s runs", fn.first, fn.second, family.c_str());
    std::printf(".\n");
  }
  std::printf("\nTotals: %d of %d families right by median over seeds (target: at least 10 of 12); false alarms %s "
              "(target: at most 1 in 20 per model); %.0f s%s.\n",
              families_right, families_scored, alarms_ok ? "within target" : "ABOVE target", elapsed(),
              cut ? " (time limit reached: runs cut)" : "");
  if (!o.json.empty()) {
    std::ofstream j(o.json);
    j << "{\"families_right\":" << families_right << ",\"families_scored\":" << families_scored << ",\"runs\":[\n";
    for (std::size_t i = 0; i < runs.size(); ++i) j << (i ? ",\n" : "") << json_run(runs[i]);
    j << "\n]}\n";
    if (!j) {
      std::fprintf(stderr, "%s: write failed\n", o.json.c_str());
      return 1;
    }
  }
  return errors == 0 ? 0 : 1;
}
