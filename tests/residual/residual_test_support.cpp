#include "residual_test_support.hpp"

#include <cstdio>

#include "dynid/report/residual_report.hpp"
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
  out.recorded = ingest::assemble_run(out.announcement, chunks);
  out.segments = ingest::preprocess_offline(out.recorded);
  return out;
}

void print_comparison(const std::string& title, const EffectComparison& c) {
  std::printf("\n== %s ==\n%s", title.c_str(), report::format_comparison_text(c).c_str());
}

void print_ranking(const ScreenResult& screen, std::size_t top) {
  std::printf("%s", report::format_screen_text(screen, top).c_str());
}

}  // namespace dynid::residual::test
