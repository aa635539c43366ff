#include "dynid/residual/simex_against_iv.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <boost/math/distributions/normal.hpp>

namespace dynid::residual {
namespace {

bool same_columns(const IvFit& iv, const SimexFit& simex) {
  const auto n = static_cast<Eigen::Index>(iv.parameters.size());
  if (iv.model != simex.model || simex.parameters.size() != iv.parameters.size() || iv.value.size() != n ||
      iv.hac_std.size() != n || iv.difference_std.size() != n || simex.value.size() != n || simex.std.size() != n ||
      simex.monte_carlo_std.size() != n || simex.level_std.size() != n)
    return false;
  for (std::size_t k = 0; k < iv.parameters.size(); ++k)
    if (iv.parameters[k].name != simex.parameters[k].name) return false;
  return true;
}

bool both_estimate(const IvFit& iv, const SimexFit& simex, Eigen::Index j) {
  return std::isfinite(iv.value(j)) && std::isfinite(iv.hac_std(j)) && std::isfinite(iv.difference_std(j)) &&
         std::isfinite(simex.value(j)) && std::isfinite(simex.std(j));
}

// Var(IV - SIMEX) under "SIMEX's noise model holds" (header).
double difference_variance(const IvFit& iv, const SimexFit& simex, Eigen::Index j) {
  const auto square = [](double x) { return std::isfinite(x) ? x * x : 0.0; };
  return square(iv.difference_std(j)) + square(simex.monte_carlo_std(j)) + square(simex.level_std(j));
}

}  // namespace

SimexAgainstIv compare_simex_with_iv(const IvFit& iv, const SimexFit& simex, double family_level) {
  SimexAgainstIv out;
  if (iv.refused || !simex.corrected() || !same_columns(iv, simex)) return out;
  std::vector<Eigen::Index> common;
  for (Eigen::Index j = 0; j < iv.value.size(); ++j)
    if (both_estimate(iv, simex, j)) common.push_back(j);
  if (common.empty()) return out;
  out.compared = true;
  out.parameters = static_cast<int>(common.size());
  out.level = family_level / static_cast<double>(common.size());
  const double z_bound = boost::math::quantile(boost::math::complement(boost::math::normal(), out.level / 2.0));
  out.simex_stands = true;
  for (const Eigen::Index j : common) {
    const std::string& name = iv.parameters[static_cast<std::size_t>(j)].name;
    if (!(simex.std(j) < iv.hac_std(j))) {
      out.simex_stands = false;
      out.deciding = name;
      out.largest_z = std::numeric_limits<double>::quiet_NaN();
      return out;
    }
    const double variance = difference_variance(iv, simex, j);
    const double z = variance > 0.0 ? std::abs(iv.value(j) - simex.value(j)) / std::sqrt(variance)
                                    : (iv.value(j) == simex.value(j) ? 0.0 : std::numeric_limits<double>::infinity());
    if (out.deciding.empty() || z > out.largest_z) {
      out.deciding = name;
      out.largest_z = z;
    }
    if (z > z_bound) out.simex_stands = false;
  }
  return out;
}

std::string SimexAgainstIv::statement() const {
  if (!compared) return "SIMEX not compared with IV (IV refused, no noise corrected, or other columns)";
  if (std::isnan(largest_z))
    return "IV kept: SIMEX is not more precise for " + deciding;
  char figures_text[160];
  std::snprintf(figures_text, sizeof figures_text, "largest |IV - SIMEX| %.2f std of their difference (%s), level %.2g per parameter",
                largest_z, deciding.c_str(), level);
  const std::string figures = figures_text;
  return simex_stands ? "SIMEX agrees with IV and is more precise: SIMEX published (" + figures + ")"
                      : "SIMEX disagrees with IV, its noise model does not hold: IV kept (" + figures + ")";
}

}  // namespace dynid::residual
