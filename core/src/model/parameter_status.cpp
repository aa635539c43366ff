#include "dynid/model/parameter_status.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "dynid/error.hpp"

namespace dynid::model {
namespace {

// Four significant digits for reasons read by people (1500 kg, not 1.5e+03).
std::string short_number(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

std::string with_unit(double x, const std::string& unit) {
  return unit.empty() || unit == "-" ? short_number(x) : short_number(x) + " " + unit;
}

std::string needs(const ParameterInfo& p) {
  return p.excited_by.empty() ? std::string("a run that moves its column") : p.excited_by;
}

// How far outside the bounds `value` lies (0 when within).
double outside_by(const ParameterInfo& p, double value) {
  if (p.within_bounds(value)) return 0.0;
  if (p.lower && value <= *p.lower) return *p.lower - value;
  if (p.upper && value >= *p.upper) return value - *p.upper;
  return 0.0;
}

}  // namespace

std::optional<double> excitation_scale(const ParameterInfo& p) {
  if (p.a_priori && *p.a_priori != 0.0 && std::isfinite(*p.a_priori)) return std::abs(*p.a_priori);
  if (p.typical && *p.typical > 0.0 && std::isfinite(*p.typical)) return *p.typical;
  if (p.lower && p.upper && std::isfinite(*p.upper - *p.lower) && *p.upper > *p.lower)
    return *p.upper - *p.lower;
  return std::nullopt;
}

Eigen::VectorXd column_norms(const ls::Accumulator& accumulator) {
  const Eigen::Index n = accumulator.parameter_count();
  return accumulator.augmented_r().topLeftCorner(n, n).colwise().norm().transpose();
}

ModelVerdict classify_parameters(const std::vector<ParameterInfo>& parameters,
                                 const ls::Estimate& estimate,
                                 const Eigen::Ref<const Eigen::VectorXd>& norms,
                                 const StatusRules& rules) {
  const auto n = static_cast<std::size_t>(estimate.value.size());
  if (parameters.size() != n || static_cast<std::size_t>(norms.size()) != n ||
      estimate.structure.status.size() != n)
    throw InputError("classify_parameters: " + std::to_string(parameters.size()) +
                     " parameters and " + std::to_string(norms.size()) + " column norms for " +
                     std::to_string(n) + " estimated");
  ModelVerdict out;
  out.parameters.resize(n);
  const double residual = estimate.residual_norm;
  // Rules 1 and 2.
  for (std::size_t j = 0; j < n; ++j) {
    const auto k = static_cast<Eigen::Index>(j);
    const ParameterInfo& p = parameters[j];
    ParameterVerdict& v = out.parameters[j];
    v.status = estimate.structure.status[j];
    if (v.status == ls::ParameterStatus::kEliminated) v.reason = "not excited: needs " + needs(p);
    if (v.status != ls::ParameterStatus::kIdentified) continue;
    const double value = estimate.value(k), sigma = estimate.standard_deviation(k);
    if (const auto scale = excitation_scale(p)) {
      const double term = norms(k) * *scale;
      if (std::isfinite(residual) && term < residual && !(std::abs(value) >= 2.0 * sigma)) {
        v.status = ls::ParameterStatus::kNotExcited;
        v.reason = "not excited: at " + with_unit(*scale, p.unit) + " its term is " +
                   short_number(term / residual) + " of the residual and it is within 2 std of 0; needs " +
                   needs(p);
        continue;
      }
      if (!(sigma < *scale)) {  // NaN std: no information either
        v.status = ls::ParameterStatus::kNotExcited;
        v.reason = "not excited: std " + with_unit(sigma, p.unit) + " >= " +
                   with_unit(*scale, p.unit) + ", the run cannot tell it from 0; needs " + needs(p);
        continue;
      }
    }
    const double outside = outside_by(p, value);
    if (outside > 0.0 && outside > rules.implausible_sigmas * sigma) {
      v.status = ls::ParameterStatus::kImplausible;
      v.reason = "outside its bounds " + p.bounds_text() + " by " +
                 (sigma > 0.0 ? short_number(outside / sigma) + " std" : with_unit(outside, p.unit));
    }
  }
  // Rule 3: the smallest relative std among those still identified.
  double smallest = std::numeric_limits<double>::infinity();
  std::string smallest_name;
  for (std::size_t j = 0; j < n; ++j) {
    const double r = estimate.relative_std_percent(static_cast<Eigen::Index>(j));
    if (out.parameters[j].status == ls::ParameterStatus::kIdentified && std::isfinite(r) && r < smallest) {
      smallest = r;
      smallest_name = parameters[j].name;
    }
  }
  for (std::size_t j = 0; j < n; ++j) {
    ParameterVerdict& v = out.parameters[j];
    if (v.status != ls::ParameterStatus::kIdentified) continue;
    const double r = estimate.relative_std_percent(static_cast<Eigen::Index>(j));
    if (!(r <= rules.poor_relative_std_percent)) {
      v.status = ls::ParameterStatus::kPoorlyIdentified;
      v.reason = "relative std " + short_number(r) + " % > " +
                 short_number(rules.poor_relative_std_percent) + " %";
    } else if (r > rules.well_estimated_percent && std::isfinite(smallest) &&
               r > rules.k_smallest * smallest) {
      v.status = ls::ParameterStatus::kPoorlyIdentified;
      v.reason = "relative std " + short_number(r) + " % > " + short_number(rules.k_smallest) +
                 " x the smallest (" + short_number(smallest) + " %, " + smallest_name + ")";
    }
  }
  // The model-level line.
  bool excited = false, unexcited = false;
  std::vector<std::string> what;
  for (std::size_t j = 0; j < n; ++j) {
    const auto s = out.parameters[j].status;
    if (s == ls::ParameterStatus::kNotExcited || s == ls::ParameterStatus::kEliminated) {
      unexcited = true;
      const std::string need = needs(parameters[j]);
      if (std::find(what.begin(), what.end(), need) == what.end()) what.push_back(need);
    } else if (s != ls::ParameterStatus::kDependent) {
      excited = true;
    }
  }
  if (unexcited && !excited) {
    out.not_excited = "needs ";
    for (std::size_t i = 0; i < what.size(); ++i)
      out.not_excited += (i == 0 ? "" : (i + 1 == what.size() ? " and " : ", ")) + what[i];
  }
  return out;
}

}  // namespace dynid::model
