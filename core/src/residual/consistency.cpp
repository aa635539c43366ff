#include "dynid/residual/consistency.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>

#include "dynid/error.hpp"
#include "dynid/model/parameter_status.hpp"
#include "folded_rows.hpp"
#include "hac_wald.hpp"

namespace dynid::residual {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, pattern, a, b, c);
  return buf;
}

// Relative std within DYCARO's quality limit (parameter_status.hpp rule 3's absolute one).
bool precise(const ModelParameters& m, Eigen::Index i) {
  return std::abs(m.std(i)) <=
         model::StatusRules{}.poor_relative_std_percent / 100.0 * std::abs(m.value(i));
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

// The value and HAC std of parameter j of `m`, when the run excites it: finite, and not
// parameter_status.hpp rule 1b (a std at least the quantity's typical magnitude says the run
// cannot tell it from zero, and its value is whatever the other columns leave). lookup: and
// within DYCARO's quality limit (the header: beyond it least squares' bias is not bounded by the
// std), which is what is compared.
bool excited(const ModelParameters& m, std::size_t j, double& value, double& std) {
  const auto i = static_cast<Eigen::Index>(j);
  if (j >= m.parameters.size() || !std::isfinite(m.value(i)) || !std::isfinite(m.std(i)))
    return false;
  if (const std::optional<double> scale = model::excitation_scale(m.parameters[j]);
      scale && m.std(i) >= *scale)
    return false;
  value = m.value(i);
  std = m.std(i);
  return true;
}

bool lookup(const ModelParameters& m, std::size_t j, double& value, double& std) {
  return excited(m, j, value, std) && precise(m, static_cast<Eigen::Index>(j));
}

// The index in `m` of the parameter measuring `quantity` in `unit`, or npos.
std::size_t measuring(const ModelParameters& m, const std::string& quantity,
                      const std::string& unit) {
  for (std::size_t j = 0; j < m.parameters.size(); ++j)
    if (m.parameters[j].quantity == quantity && m.parameters[j].unit == unit) return j;
  return std::string::npos;
}

ParameterAgreement compare(const std::string& parameter, const std::string& unit, const std::string& first, double a,
                           double sa, const std::string& second, double b, double sb) {
  ParameterAgreement out{parameter, unit, first, second, {}, {}, a, sa, b, sb};
  const double s = std::sqrt(sa * sa + sb * sb);
  out.z = s > 0.0 ? (a - b) / s : (a == b ? 0.0 : std::numeric_limits<double>::infinity());
  out.p_value = std::isfinite(out.z) ? 2.0 * boost::math::cdf(boost::math::complement(boost::math::normal(), std::abs(out.z))) : 0.0;
  return out;
}

std::vector<ParameterAgreement> comparisons_of(const std::vector<ModelParameters>& models,
                                               const std::map<std::string, double>& reference) {
  std::vector<ParameterAgreement> out;
  for (std::size_t i = 0; i < models.size(); ++i) {
    for (std::size_t j = 0; j < models[i].parameters.size(); ++j) {
      const model::ParameterInfo& p = models[i].parameters[j];
      double a = 0.0, sa = 0.0;
      if (!lookup(models[i], j, a, sa)) continue;
      // Only parameters that declare one physical quantity are compared across models: a name
      // alone says nothing (the ax and ay sensors' scales; the clutch model's J_e and the
      // locked driveline's J_e + J_in).
      for (std::size_t k = i + 1; k < models.size() && !p.quantity.empty(); ++k) {
        double b = 0.0, sb = 0.0;
        if (lookup(models[k], measuring(models[k], p.quantity, p.unit), b, sb)) {
          out.push_back(compare(p.name, p.unit, models[i].model, a, sa, models[k].model, b, sb));
          out.back().first_estimator = models[i].estimator;
          out.back().second_estimator = models[k].estimator;
        }
      }
      if (const auto r = reference.find(p.reference_key()); r != reference.end()) {
        out.push_back(compare(p.name, p.unit, models[i].model, a, sa, kReference, r->second, 0.0));
        out.back().first_estimator = models[i].estimator;
      }
    }
  }
  return out;
}

const ModelParameters* named(const std::vector<ModelParameters>& models, const std::string& name) {
  for (const ModelParameters& m : models)
    if (m.model == name) return &m;
  return nullptr;
}

std::string measured_side_of(const std::vector<ModelParameters>& models, const std::string& name) {
  const ModelParameters* m = named(models, name);
  return m == nullptr || m->measured_side.empty() ? "its measured side" : join(m->measured_side);
}

// Among the comparisons of `first` with `second`: one common ratio? (weighted mean of the
// log-ratios, their homogeneity chi-square).
ScaleFinding scale_of(const std::vector<ParameterAgreement>& pair, double level) {
  ScaleFinding f;
  f.first = pair.front().first;
  f.second = pair.front().second;
  double sw = 0.0, swr = 0.0;
  std::vector<std::pair<double, double>> logs;  // log-ratio, its std
  for (const ParameterAgreement& c : pair) {
    if (c.first_value == 0.0 || c.second_value == 0.0 || (c.first_value > 0.0) != (c.second_value > 0.0)) continue;
    const double r = std::log(c.first_value / c.second_value);
    const double s = std::hypot(c.first_std / c.first_value, c.second_std / c.second_value);
    if (!(s > 0.0)) continue;
    logs.emplace_back(r, s);
    sw += 1.0 / (s * s);
    swr += r / (s * s);
    f.parameters.push_back(c.parameter);
  }
  if (logs.empty()) {
    f.one_ratio = false;
    return f;
  }
  const double mean = swr / sw;
  f.ratio = std::exp(mean);
  f.ratio_std = f.ratio / std::sqrt(sw);
  double chi2 = 0.0;
  for (const auto& [r, s] : logs) chi2 += (r - mean) * (r - mean) / (s * s);
  if (logs.size() > 1)
    f.homogeneity_p = boost::math::cdf(
        boost::math::complement(boost::math::chi_squared(static_cast<double>(logs.size() - 1)), chi2));
  f.one_ratio = f.homogeneity_p >= level;
  return f;
}

// Which model of a disagreeing pair a reference value vindicates: the one whose comparison with
// the reference is not significant while the other's is.
std::string off_by_reference(const ScaleFinding& f, const std::vector<ParameterAgreement>& all) {
  bool first_off = false, second_off = false, first_seen = false, second_seen = false;
  for (const ParameterAgreement& c : all) {
    if (c.second != kReference) continue;
    if (c.first == f.first) {
      first_seen = true;
      first_off = first_off || c.significant;
    }
    if (c.first == f.second) {
      second_seen = true;
      second_off = second_off || c.significant;
    }
  }
  if (first_seen && second_seen && first_off != second_off) return first_off ? f.first : f.second;
  return "";
}

void describe(ScaleFinding& f, const std::vector<ModelParameters>& models) {
  const std::string ratio = format("%.4g +- %.2g", f.ratio, f.ratio_std);
  if (!f.one_ratio) {
    f.statement = f.first + " and " + f.second + " disagree on " + join(f.parameters) +
                  " by different ratios (homogeneity p = " + format("%.2g", f.homogeneity_p) +
                  "): not one scale; an effect one of them lacks, or a parameter they name alike but mean differently";
    return;
  }
  if (f.second == kReference) {
    f.off = f.first;
    f.statement = f.first + "'s " + join(f.parameters) + " is " + ratio + " times the reference: a scale error of " +
                  measured_side_of(models, f.first) +
                  " (or of the radius or ratio its force is computed with), or an effect the model lacks";
    return;
  }
  std::string where = "a scale error of " + f.first + "'s measured side (" + measured_side_of(models, f.first) +
                      ") or of " + f.second + "'s (" + measured_side_of(models, f.second) +
                      "), or of the radius or ratio one of them computes its force with";
  if (!f.off.empty()) {
    const double s = f.off == f.first ? f.ratio : 1.0 / f.ratio;
    where = "the reference agrees with " + (f.off == f.first ? f.second : f.first) + ": " +
            measured_side_of(models, f.off) + format(" reads %+.1f %%", 100.0 * (s - 1.0)) + " (or " + f.off +
            "'s radius or ratio is off by as much)";
  }
  f.statement = f.first + "'s parameters are " + ratio + " times " + f.second + "'s (" + join(f.parameters) +
                (f.parameters.size() > 1 ? ", one common ratio" : "") + "): " + where;
}

}  // namespace

ModelParameters hac_parameters(const model::Model& model, const std::vector<std::string>& effects,
                               const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                               int odmf, const FitOptions& options) {
  FitOptions fold_options = options;
  fold_options.series = false;
  const detail::FoldedRows rows =
      detail::fold_rows(model, effects, run, sample_rate_hz, odmf, fold_options, true, nullptr);
  const detail::Evaluation fit = detail::evaluate(rows, {}, {});
  const auto width = static_cast<Eigen::Index>(rows.parameters.size());
  const detail::WaldTest hac = detail::hac_wald_test(rows, fit.all.value, fit.estimator_weights, 0, width, odmf);
  ModelParameters out{model.name(), model.measured_side(), rows.parameters, fit.all.value,
                      hac.stds.size() == width ? hac.stds : Eigen::VectorXd::Constant(width, kNaN)};
  return out;
}

ModelParameters with_instruments(ModelParameters ls, const IvFit& iv) {
  const auto n = ls.value.size();
  if (!iv.replaces_least_squares() || iv.value.size() != n || iv.hac_std.size() != n ||
      iv.parameters.size() != ls.parameters.size())
    return ls;
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::isfinite(ls.value(i)) && std::isfinite(iv.value(i)) && std::isfinite(iv.hac_std(i)))
      ls.value(i) = iv.value(i), ls.std(i) = iv.hac_std(i);
  ls.estimator = "IV";
  return ls;
}

ModelParameters compared_parameters(const model::Model& model,
                                    const std::vector<std::string>& effects,
                                    const std::vector<ingest::PreprocessedSegment>& run,
                                    const ingest::RunAnnouncement& announcement) {
  const double rate = announcement.sample_rate_hz;
  const int odmf = announcement.preprocessing.odmf;
  ModelParameters ls = hac_parameters(model, effects, run, rate, odmf);
  IvOptions options;
  options.preprocessing = announcement.preprocessing;
  try {
    return with_instruments(std::move(ls), iv_fit(model, effects, run, rate, odmf, options));
  } catch (const InputError&) {
    return ls;  // no IV fit of these rows: least squares' values are the published ones
  }
}

bool Consistency::consistent() const {
  return std::none_of(comparisons.begin(), comparisons.end(), [](const ParameterAgreement& c) { return c.significant; });
}

std::string Consistency::statement() const {
  if (comparisons.empty() && !not_compared.empty())
    return "nothing compared: the parameters two models share, or that have a reference value, are "
           "not precise enough on this run (not compared)";
  if (comparisons.empty()) return "no parameter to compare: no two models share one, and no reference value applies";
  if (consistent())
    return "consistent: " + std::to_string(comparisons.size()) +
           " comparisons of shared parameters and reference values, none beyond the level " + format("%.2g", level);
  std::string out = "inconsistent:";
  for (const ScaleFinding& f : scales) out += " " + f.statement + ";";
  out.pop_back();
  return out;
}

namespace {

// The parameters comparisons_of would have compared (a quantity another model measures, or a
// reference value) but left out for their precision alone.
std::vector<std::string> imprecise_of(const std::vector<ModelParameters>& models,
                                      const std::map<std::string, double>& reference) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < models.size(); ++i) {
    const ModelParameters& m = models[i];
    for (std::size_t j = 0; j < m.parameters.size(); ++j) {
      const model::ParameterInfo& p = m.parameters[j];
      bool shared = reference.count(p.reference_key()) > 0;
      for (std::size_t k = 0; k < models.size() && !shared && !p.quantity.empty(); ++k)
        shared = k != i && measuring(models[k], p.quantity, p.unit) != std::string::npos;
      double value = 0.0, std = 0.0;
      if (!shared || !excited(m, j, value, std) || precise(m, static_cast<Eigen::Index>(j)))
        continue;
      out.push_back(m.model + ": " + p.name + " = " + format("%.4g", value) + " +- " +
                    format("%.2g", std) + " " + p.unit + " (" +
                    format("%.0f", 100.0 * std / std::abs(value)) + " % relative std, beyond the " +
                    format("%.0f", model::StatusRules{}.poor_relative_std_percent) +
                    " % of an identified value)");
    }
  }
  return out;
}

}  // namespace

Consistency check_consistency(const std::vector<ModelParameters>& models,
                              const std::map<std::string, double>& reference, double family_error_rate) {
  Consistency out;
  out.comparisons = comparisons_of(models, reference);
  out.not_compared = imprecise_of(models, reference);
  out.tests = static_cast<int>(out.comparisons.size());
  out.level = out.tests > 0 ? family_error_rate / out.tests : 0.0;
  for (ParameterAgreement& c : out.comparisons) c.significant = c.p_value < out.level;
  // One finding per pair with a significant disagreement, resting on all its comparisons.
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const ParameterAgreement& c : out.comparisons)
    if (c.significant && std::find(pairs.begin(), pairs.end(), std::make_pair(c.first, c.second)) == pairs.end())
      pairs.emplace_back(c.first, c.second);
  for (const auto& [first, second] : pairs) {
    std::vector<ParameterAgreement> pair;
    for (const ParameterAgreement& c : out.comparisons)
      if (c.first == first && c.second == second) pair.push_back(c);
    ScaleFinding f = scale_of(pair, out.level);
    if (second != kReference) f.off = off_by_reference(f, out.comparisons);
    describe(f, models);
    out.scales.push_back(std::move(f));
  }
  return out;
}

}  // namespace dynid::residual
