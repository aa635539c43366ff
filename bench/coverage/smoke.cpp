#include "smoke.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "car/clean_run.hpp"
#include "summary.hpp"

namespace dynid::benchcoverage {
namespace {

constexpr double kErrorBound = 0.05;
constexpr double kSameEstimate = 1e-9;  // relative: one fold of the same rows, rounding only
// The lateral run's parameters with a truth: lateral_bicycle's 3, lateral_bicycle_no_vy's 4.
constexpr std::size_t kLateralParameters = 7;

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

// The failed checks of one seed's samples, in words.
std::vector<std::string> check_seed(const SeedRun& r) {
  std::vector<std::string> failed;
  const std::string seed = "seed " + std::to_string(r.seed) + ": ";
  if (!r.error.empty()) failed.push_back(seed + r.error);
  if (r.samples.size() != kLateralParameters)
    failed.push_back(seed + std::to_string(r.samples.size()) + " parameters with a truth, not " +
                     std::to_string(kLateralParameters));
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

// A mirrored run carries the negated noise of its seed's run: per channel, the two runs' noise
// (their samples less the noise-free run's) sum to within the DBC's rounding: below kMirrorShare
// of the noise's rms (the rounding of three decodes is 18 % of the steering angle's noise on this
// car, 12 % of the engine speed's, 1e-3 or less on the float channels), where noise that was not
// negated would give 141 % (independent) or 200 % (the same).
constexpr double kMirrorShare = 0.25;

std::vector<std::string> check_mirror(const car::VehicleProfile& profile, const std::filesystem::path& work_dir) {
  using benchcar::Manoeuvre;
  const auto quiet = benchcar::clean_run(profile, Manoeuvre::kLateral, 1001, 0.0, work_dir).product.recorded;
  const auto noisy = benchcar::clean_run(profile, Manoeuvre::kLateral, 1001, 1.0, work_dir).product.recorded;
  const auto mirror = benchcar::clean_run(profile, Manoeuvre::kLateral, 1001, 1.0, work_dir, true).product.recorded;
  std::vector<std::string> failed;
  if (quiet.samples.rows() != noisy.samples.rows() || mirror.samples.rows() != noisy.samples.rows())
    return {"mirror: the runs differ in length"};
  int noisy_channels = 0;
  for (Eigen::Index c = 0; c < noisy.samples.cols(); ++c) {
    const Eigen::VectorXd noise = noisy.samples.col(c) - quiet.samples.col(c);
    const Eigen::VectorXd sum = noise + (mirror.samples.col(c) - quiet.samples.col(c));
    if (noise.norm() == 0.0) continue;
    ++noisy_channels;
    const std::string& name = noisy.announcement.channels[static_cast<std::size_t>(c)].name;
    std::printf("mirror %-22s noise rms %.4g, sum with the mirrored run's rms %.3g\n", name.c_str(),
                noise.norm() / std::sqrt(static_cast<double>(noise.size())), sum.norm() / std::sqrt(static_cast<double>(sum.size())));
    if (!(sum.norm() <= kMirrorShare * noise.norm())) failed.push_back("mirror: " + name + "'s noise is not negated");
  }
  if (noisy_channels == 0) failed.push_back("mirror: no channel carries noise");
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
  if (rows.size() != kLateralParameters)
    failed.push_back("summary: " + std::to_string(rows.size()) + " rows, not " +
                     std::to_string(kLateralParameters));
  for (const std::string& f : check_mirror(profile, work_dir)) failed.push_back(f);
  for (const std::string& f : failed) std::printf("FAIL %s\n", f.c_str());
  std::printf("%zu failed checks\n", failed.size());
  return static_cast<int>(failed.size());
}

}  // namespace dynid::benchcoverage
