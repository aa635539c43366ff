#include "json_out.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

namespace dynid::benchcoverage {
namespace {

// JSON has no NaN: a value that is not finite (a parameter not identifiable) is null.
nlohmann::json number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

nlohmann::json sample_json(const ParameterSample& s) {
  return {{"model", s.model},         {"parameter", s.parameter}, {"truth", number(s.truth)},
          {"value", number(s.value)}, {"std", number(s.std)},     {"hac_value", number(s.hac_value)},
          {"hac_std", number(s.hac_std)},     {"iv_value", number(s.iv_value)}, {"iv_std", number(s.iv_std)},
          {"iv_hac_std", number(s.iv_hac_std)}, {"iv_difference_std", number(s.iv_difference_std)},
          {"dwh_rejects", s.dwh_rejects},     {"iv_refused", s.iv_refused},
          {"iv_instrument_f", number(s.iv_instrument_f)}, {"simex_value", number(s.simex_value)},
          {"simex_std", number(s.simex_std)}, {"simex_mc_std", number(s.simex_mc_std)},
          {"simex_level_std", number(s.simex_level_std)}, {"simex_corrected", s.simex_corrected},
          {"simex_over_iv", s.simex_over_iv}};
}

nlohmann::json run_json(const SeedRun& r) {
  nlohmann::json samples = nlohmann::json::array();
  for (const ParameterSample& s : r.samples) samples.push_back(sample_json(s));
  return {{"manoeuvre", benchcar::manoeuvre_name(r.manoeuvre)},
          {"seed", r.seed},
          {"mirrored", r.mirrored},
          {"seconds", r.seconds},
          {"error", r.error},
          {"parameters", samples}};
}

nlohmann::json std_json(const StdCoverage& c) {
  return {{"mean_std_pct", number(c.mean_std_pct)},
          {"within_2std", number(c.within_2std)},
          {"mean_error_over_std", number(c.error_over_std)}};
}

nlohmann::json published_json(const PublishedCoverage& c) {
  return {{"seeds", c.seeds},
          {"by_iv", c.by_iv},
          {"by_simex", c.by_simex},
          {"mean_error_pct", number(c.mean_error_pct)},
          {"scatter_pct", number(c.scatter_pct)},
          {"std", std_json(c.std)}};
}

nlohmann::json row_json(const ParameterCoverage& r) {
  return {{"model", r.model},
          {"parameter", r.parameter},
          {"truth", number(r.truth)},
          {"seeds", r.seeds},
          {"mean_error_pct", number(r.mean_error_pct)},
          {"scatter_pct", number(r.scatter_pct)},
          {"table", std_json(r.table)},
          {"hac", std_json(r.hac)},
          {"iv",
           {{"seeds", r.iv.seeds},
            {"refused", r.iv.refused},
            {"mean_error_pct", number(r.iv.mean_error_pct)},
            {"scatter_pct", number(r.iv.scatter_pct)},
            {"textbook", std_json(r.iv.textbook)},
            {"hac", std_json(r.iv.hac)},
            {"dwh_rejections", number(r.iv.dwh_rejections)}}},
          {"simex",
           {{"seeds", r.simex.seeds},
            {"corrected", r.simex.corrected},
            {"mean_error_pct", number(r.simex.mean_error_pct)},
            {"scatter_pct", number(r.simex.scatter_pct)},
            {"mean_monte_carlo_std_pct", number(r.simex.mean_monte_carlo_std_pct)},
            {"std", std_json(r.simex.std)}}},
          {"without_simex", published_json(r.without_simex)},
          {"published", published_json(r.published)}};
}

}  // namespace

bool write_json(const std::string& path, const std::vector<SeedRun>& runs, const std::vector<ParameterCoverage>& rows,
                double seconds) {
  nlohmann::json out = {{"seconds", seconds}, {"runs", nlohmann::json::array()}, {"summary", nlohmann::json::array()}};
  for (const SeedRun& r : runs) out["runs"].push_back(run_json(r));
  for (const ParameterCoverage& r : rows) out["summary"].push_back(row_json(r));
  std::ofstream file(path);
  file << out.dump(1) << "\n";
  if (!file) std::fprintf(stderr, "%s: write failed\n", path.c_str());
  return static_cast<bool>(file);
}

}  // namespace dynid::benchcoverage
