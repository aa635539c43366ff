#include "smoke.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "summary.hpp"

namespace dynid::benchcoverage {
namespace {

constexpr double kErrorBound = 0.05;
constexpr double kSameEstimate = 1e-9;  // relative: one fold of the same rows, rounding only

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

// The failed checks of one seed's samples, in words.
std::vector<std::string> check_seed(const SeedRun& r) {
  std::vector<std::string> failed;
  const std::string seed = "seed " + std::to_string(r.seed) + ": ";
  if (!r.error.empty()) failed.push_back(seed + r.error);
  if (r.samples.size() != 3) failed.push_back(seed + std::to_string(r.samples.size()) + " parameters with a truth, not 3");
  for (const ParameterSample& s : r.samples) {
    const std::string what = seed + s.model + " " + s.parameter;
    std::printf("%s = %.6g (table std %.3g, HAC std %.3g) against %.6g: error %+.2f %%\n", what.c_str(), s.value, s.std,
                s.hac_std, s.truth, 100.0 * s.relative_error());
    if (!positive(s.value) || !positive(s.std) || !positive(s.hac_std)) failed.push_back(what + ": not finite and positive");
    if (!(std::abs(s.hac_value - s.value) <= kSameEstimate * std::abs(s.value)))
      failed.push_back(what + ": the HAC fit's value differs from the table's");
    if (!(std::abs(s.relative_error()) <= kErrorBound)) failed.push_back(what + ": error above 5 %");
    if (!s.iv_refused.empty()) failed.push_back(what + ": IV refused: " + s.iv_refused);
    if (!positive(s.iv_value) || !positive(s.iv_std) || !positive(s.iv_hac_std))
      failed.push_back(what + ": IV value or std not finite and positive");
    if (!(std::abs(s.iv_relative_error()) <= kErrorBound)) failed.push_back(what + ": IV error above 5 %");
    if (!s.simex_corrected) failed.push_back(what + ": SIMEX corrected nothing: no measured noise reached the rows");
    if (!positive(s.simex_value) || !positive(s.simex_std) || !(s.simex_mc_std >= 0.0 && s.simex_mc_std < s.simex_std))
      failed.push_back(what + ": SIMEX value or std not finite and positive");
    if (!(std::abs(s.simex_relative_error()) <= kErrorBound)) failed.push_back(what + ": SIMEX error above 5 %");
  }
  return failed;
}

std::vector<std::string> check_summary(const std::vector<ParameterCoverage>& rows) {
  std::vector<std::string> failed;
  for (const ParameterCoverage& r : rows) {
    const double fields[] = {r.mean_error_pct, r.scatter_pct, r.table.mean_std_pct, r.table.within_2std,
                             r.table.error_over_std, r.hac.mean_std_pct, r.hac.within_2std, r.hac.error_over_std};
    bool finite = r.seeds == 2;
    for (double x : fields) finite = finite && std::isfinite(x);
    if (!finite) failed.push_back("summary of " + r.parameter + ": not two seeds of finite figures");
  }
  return failed;
}

}  // namespace

int run_smoke(const car::VehicleProfile& profile, const std::filesystem::path& work_dir) {
  std::vector<SeedRun> runs;
  std::vector<std::string> failed;
  for (std::uint64_t seed : {1001u, 1002u}) {
    runs.push_back(measure_seed(profile, benchcar::Manoeuvre::kLateral, seed, 1.0, work_dir));
    for (const std::string& f : check_seed(runs.back())) failed.push_back(f);
  }
  const std::vector<ParameterCoverage> rows = summarize(runs);
  std::printf("\n%s\n", markdown_table(rows).c_str());
  for (const std::string& f : check_summary(rows)) failed.push_back(f);
  if (rows.size() != 3) failed.push_back("summary: " + std::to_string(rows.size()) + " rows, not 3");
  for (const std::string& f : failed) std::printf("FAIL %s\n", f.c_str());
  std::printf("%zu failed checks\n", failed.size());
  return static_cast<int>(failed.size());
}

}  // namespace dynid::benchcoverage
