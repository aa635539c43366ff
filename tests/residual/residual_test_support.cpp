#include "residual_test_support.hpp"

#include <cmath>
#include <cstdio>

#include "sim_product_path.hpp"
#include "sim_test_support.hpp"

namespace dynid::residual::test {

ProcessedRun process(const sim::Run& run, const ingest::ModelSpec& spec, bool tare, double cutoff_hz) {
  const std::string name = run.scenario.name + "-" + std::to_string(run.seed);
  ProcessedRun out;
  out.announcement = sim::test::testcar_profile().announcement(name);
  out.announcement.models = {spec};
  out.announcement.preprocessing.cutoff_hz = cutoff_hz;
  if (tare) sim::test::tare_for(run, sim::test::load_scenario_text("tare.toml")).apply(out.announcement);
  const std::vector<ingest::Chunk> chunks = sim::test::replay_chunks(run, name);
  out.segments = ingest::preprocess_offline(ingest::assemble_run(out.announcement, chunks));
  return out;
}

void print_comparison(const std::string& title, const EffectComparison& c) {
  std::printf("\n== %s: add %s to %s ==\n", title.c_str(), c.effect.c_str(), c.before.model.c_str());
  std::printf("%-30s %14s %12s %9s | %14s %12s %9s\n", "parameter", "before", "std", "err %", "after", "std",
              "err %");
  for (const ParameterChange& p : c.parameters) {
    if (p.name.find('@') != std::string::npos && !p.truth) continue;  // profile knots: too many to list
    std::printf("%-30s %14.6g %12.4g %9.2f | %14.6g %12.4g %9.2f\n", p.name.c_str(), p.before,
                p.std_before, p.error_before_percent(), p.after, p.std_after, p.error_after_percent());
  }
  for (std::size_t g = 0; g < c.before.groups.size(); ++g) {
    const GroupFit& b = c.before.groups[g];
    const GroupFit& a = c.after.groups[g];
    std::printf("group %-12s residual RMS in sample %.5g -> %.5g, held out %.5g -> %.5g; relative norm %.4f -> %.4f\n",
                b.group.c_str(), b.rms_in_sample, a.rms_in_sample, b.rms_held_out, a.rms_held_out,
                b.relative_norm_in_sample, a.relative_norm_in_sample);
  }
  std::printf("weighted RMS: in sample %.1f %% lower, held out %.1f %% lower\n", 100.0 * c.in_sample_drop(),
              100.0 * c.held_out_drop());
}

void print_ranking(const ScreenResult& screen, std::size_t top) {
  std::printf("%-34s %-12s %9s %9s %10s %6s %s\n", "candidate", "kind", "in-samp %", "held-out %", "F", "folds",
              "significant");
  for (std::size_t i = 0; i < screen.candidates.size() && i < top; ++i) {
    const CandidateScore& c = screen.candidates[i];
    if (!c.evaluated) {
      std::printf("%-34s %-12s not tested: %s\n", c.effect.c_str(), kind_name(c.kind), c.note.c_str());
      continue;
    }
    std::printf("%-34s %-12s %9.2f %9.2f %10.3g %3d/%-2d %s\n", c.effect.c_str(), kind_name(c.kind),
                100.0 * c.in_sample_drop, 100.0 * c.held_out_drop, c.f_statistic, c.folds_improved, c.folds,
                c.significant ? "yes" : "no");
  }
  std::printf("verdict: %s\n", screen.verdict().c_str());
}

}  // namespace dynid::residual::test
