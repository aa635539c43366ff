// dynid-bench-coverage: do the reported standard deviations cover the error? (issue 16 item 3,
// the measurement; docs/ACCURACY.md "Coverage of the standard deviations (second car)"). For
// every manoeuvre of the second car (bench/trace/car) and N seeds (1001 .. 1000 + N, the clean
// runs of dynid-bench-trace's false-alarm count): a clean run with the car's normal sensor noise
// through the product's data path, every model of the manoeuvre fitted as benchcar.toml declares
// it, and per parameter with a known truth the error against the estimate table's std (DYCARO's
// weighted LS) and the HAC std of `dynid consistency`; and the same for the instrumental-variable
// estimate (residual::iv_fit, issue 16 item 2) with how often its Durbin-Wu-Hausman test calls LS
// biased at 1 %; and the SIMEX correction of LS for the measured channel noise (residual::simex_fit)
// with what a table would publish with it. `--antithetic` runs every seed twice, with its noise
// and with the mirror of it, so that the mean error carries the bias without the terms odd in the
// noise (docs/ACCURACY.md "What 20 seeds can resolve"). Prints one line per run, the markdown
// tables, a verdict per parameter against issue 16's goals and the run time; --json writes every
// run. Measurement only: no estimator is tuned here. `--smoke` is the ctest check of the harness.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include "car/product_path.hpp"
#include "goals.hpp"
#include "json_out.hpp"
#include "measure.hpp"
#include "options.hpp"
#include "smoke.hpp"
#include "summary.hpp"

namespace {

using namespace dynid;
using namespace dynid::benchcoverage;

void print_seed(const SeedRun& r) {
  std::printf("%-12s seed %llu%s (%.1f s)", benchcar::manoeuvre_name(r.manoeuvre), static_cast<unsigned long long>(r.seed),
              r.mirrored ? " mirrored" : "", r.seconds);
  if (!r.error.empty()) std::printf(" ERROR: %s", r.error.c_str());
  const std::string* model = nullptr;  // named once before its parameters: two models share names
  for (const ParameterSample& s : r.samples) {
    if (model == nullptr || *model != s.model) std::printf("; %s:", s.model.c_str());
    model = &s.model;
    const double pct = 100.0 / std::abs(s.truth);
    std::printf(" %s %+.2f %% (std %.2f, HAC %.2f; IV %+.2f %%, HAC %.2f%s; SIMEX %+.2f %%, std %.2f)", s.parameter.c_str(),
                100.0 * s.relative_error(), pct * s.std, pct * s.hac_std, 100.0 * s.iv_relative_error(),
                pct * s.iv_hac_std, s.dwh_rejects ? ", DWH" : "", 100.0 * s.simex_relative_error(), pct * s.simex_std);
  }
  std::printf("\n");
  std::fflush(stdout);
}

std::vector<SeedRun> measure_all(const Options& o, const car::VehicleProfile& profile,
                                 const std::filesystem::path& work_dir) {
  std::vector<SeedRun> runs;
  for (benchcar::Manoeuvre m : o.manoeuvres)
    for (int s = 1; s <= o.seeds; ++s)
      for (bool mirrored : {false, true}) {
        if (mirrored && !o.antithetic) continue;
        runs.push_back(measure_seed(profile, m, 1000 + static_cast<std::uint64_t>(s), o.noise_scale, work_dir,
                                    o.simex_draws, mirrored));
        print_seed(runs.back());
      }
  return runs;
}

int errors_of(const std::vector<SeedRun>& runs) {
  int n = 0;
  for (const SeedRun& r : runs) n += r.error.empty() ? 0 : 1;
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_options(argc, argv);
  const car::VehicleProfile& profile = benchcar::profile(o.profile);
  const std::filesystem::path work_dir =
      std::filesystem::temp_directory_path() / ("dynid-bench-coverage-" + std::to_string(::getpid()));
  if (o.smoke) {
    const int failures = run_smoke(profile, work_dir);
    std::filesystem::remove_all(work_dir);
    return failures == 0 ? 0 : 1;
  }
  const auto start = std::chrono::steady_clock::now();
  std::printf("dynid-bench-coverage: %d clean runs per manoeuvre (seeds 1001-%d%s), the car's sensor noise x %g\n",
              o.antithetic ? 2 * o.seeds : o.seeds, 1000 + o.seeds,
              o.antithetic ? ", each with its noise and the mirror of it" : "", o.noise_scale);
  const std::vector<SeedRun> runs = measure_all(o, profile, work_dir);
  std::filesystem::remove_all(work_dir);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<ParameterCoverage> rows = summarize(runs);
  std::printf("\n%s\n%s\n%s\n%s\n%s\n%s\n", markdown_table(rows).c_str(), verdicts(rows).c_str(),
              iv_markdown_table(rows).c_str(), iv_verdicts(rows).c_str(), without_simex_markdown_table(rows).c_str(),
              without_simex_verdicts(rows).c_str());
  std::printf("%s\n%s\n%s\n%s\n%zu runs, %d failed, %.0f s\n", simex_markdown_table(rows).c_str(),
              simex_verdicts(rows).c_str(), published_markdown_table(rows).c_str(), published_verdicts(rows).c_str(),
              runs.size(), errors_of(runs), seconds);
  if (!o.json.empty() && !write_json(o.json, runs, rows, seconds)) return 1;
  return errors_of(runs) == 0 ? 0 : 1;
}
