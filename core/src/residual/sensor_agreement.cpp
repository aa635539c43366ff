#include "dynid/residual/sensor_agreement.hpp"

#include <cmath>
#include <cstdio>

#include "dynid/error.hpp"
#include "dynid/model/channel_catalogue.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/sensor_offset.hpp"

namespace dynid::residual {
namespace {

// The offset of each fit's shift, in the sensor's unit: any value gives the same parabola and
// lines for a model linear in the sensor; 1 keeps both far above rounding.
constexpr double kShift = 1.0;
// The offset is a column of the model when shifting it changes the residual by less than this
// share of its sum of squares (rounding), and a parameter moves with it when the shift moves it
// by more than this share of its std.
constexpr double kUnseen = 1e-8;
constexpr double kMoves = 1e-3;

std::string figure(const char* format, double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

struct Published {
  std::string estimator = "least squares";
  Eigen::VectorXd value;
  Eigen::VectorXd std;
};

// publication.hpp's rules 1 (IV where its Durbin-Wu-Hausman test rejects least squares, on the
// rows it estimates); SIMEX is not computed here (the header says why).
Published published_values(const model::Model& model, const std::vector<std::string>& declared,
                           const std::vector<ingest::PreprocessedSegment>& run, double rate,
                           int odmf, const FitOptions& fit,
                           const ingest::Preprocessing& preprocessing,
                           const ModelFit& least_squares) {
  Published p;
  p.value = least_squares.estimate.value;
  p.std = least_squares.estimate.standard_deviation;
  IvOptions options;
  options.fit = fit;
  options.preprocessing = preprocessing;
  IvFit iv;
  try {
    iv = iv_fit(model, declared, run, rate, odmf, options);
  } catch (const InputError&) {
    return p;  // no IV on these rows: least squares is what is published
  }
  if (!iv.replaces_least_squares() || iv.value.size() != p.value.size()) return p;
  p.estimator = "IV";
  for (Eigen::Index i = 0; i < p.value.size(); ++i)
    if (std::isfinite(iv.value(i)) && std::isfinite(iv.hac_std(i)))
      p.value(i) = iv.value(i), p.std(i) = iv.hac_std(i);
  return p;
}

double weighted_rss(const ModelFit& f) {
  double rows = 0.0;
  for (const GroupFit& g : f.groups) rows += static_cast<double>(g.rows);
  return f.weighted_rms_in_sample * f.weighted_rms_in_sample * rows;
}

std::vector<ingest::PreprocessedSegment> shifted(
    const std::vector<ingest::PreprocessedSegment>& run, const std::string& sensor, double offset) {
  return offset_corrected(run, {SensorOffset{sensor, offset}});
}

}  // namespace

const ComparedParameter* SensorAgreement::largest() const {
  const ComparedParameter* out = nullptr;
  for (const ComparedParameter& c : compared)
    if (out == nullptr || c.moved > out->moved) out = &c;
  return out;
}

bool SensorAgreement::agrees() const {
  const ComparedParameter* m = largest();
  return m != nullptr && m->moved <= bound;
}

std::string SensorAgreement::statement() const {
  std::string sensors;
  for (const std::string& s : offsets) sensors += (sensors.empty() ? "" : ", ") + s;
  std::string out =
      effect + (offsets.empty()
                    ? ""
                    : " (" + sensors + (offsets.size() == 1 ? ": its offset" : ": their offsets") +
                          " a nuisance)");
  const ComparedParameter* m = largest();
  if (m == nullptr)
    return out + " leaves no declared parameter to compare with the published values";
  out += std::string(agrees() ? " agrees with" : " differs from") + " the published (" + estimator +
         ") parameters: " + (agrees() ? "largest move " : "") + m->name + " " +
         figure("%.4g", m->published) + " -> " + figure("%.4g", m->with_sensor) + " " + m->unit +
         ", " + figure("%.3g", m->moved) + " std of the difference (at most " +
         figure("%.3g", bound) + " at 1 % over " + std::to_string(compared.size()) +
         (compared.size() == 1 ? " parameter)" : " parameters)");
  if (!not_compared.empty()) {
    std::string names;
    for (const std::string& n : not_compared) names += (names.empty() ? "" : ", ") + n;
    out += "; not compared: " + names + " (the offset takes its place)";
  }
  return out;
}

SensorAgreement sensor_agreement(const model::Model& model,
                                 const std::vector<std::string>& declared,
                                 const std::string& effect, const std::vector<std::string>& sensors,
                                 const std::vector<ingest::PreprocessedSegment>& run, double rate,
                                 int odmf, const FitOptions& fit,
                                 const ingest::Preprocessing& preprocessing) {
  SensorAgreement out;
  out.effect = effect;
  FitOptions options = fit;
  options.series = false;
  const ModelFit declared_fit = fit_model(model, declared, run, rate, odmf, options);
  const Published published =
      published_values(model, declared, run, rate, odmf, options, preprocessing, declared_fit);
  out.estimator = published.estimator;
  options.group_weights.clear();  // the declared model's weights: one scale for every fit
  for (const GroupFit& g : declared_fit.groups)
    options.group_weights.push_back(g.sigma > 0.0 ? 1.0 / g.sigma : 0.0);
  std::vector<std::string> with = declared;
  with.push_back(effect);
  const ModelFit at_zero = fit_model(model, with, run, rate, odmf, options);
  const auto n = static_cast<Eigen::Index>(declared_fit.parameters.size());
  Eigen::VectorXd value = at_zero.estimate.value.head(n);
  Eigen::VectorXd variance = at_zero.estimate.standard_deviation.head(n).array().square();
  std::vector<bool> compared(static_cast<std::size_t>(n), true);
  const double rss = weighted_rss(at_zero);
  double rows = 0.0;
  for (const GroupFit& g : at_zero.groups) rows += static_cast<double>(g.rows);
  const double dof = rows - static_cast<double>(at_zero.parameters.size()) - 1.0;
  // Each sensor's offset is profiled in turn; the candidates read one sensor each (with several,
  // the offsets' correlation with each other is neglected).
  for (const std::string& sensor : sensors) {
    const std::optional<std::string> unit = model::channel_unit(sensor);
    if (!unit || !is_mounted_sensor(sensor, *unit)) continue;
    const ModelFit plus = fit_model(model, with, shifted(run, sensor, kShift), rate, odmf, options);
    const ModelFit minus =
        fit_model(model, with, shifted(run, sensor, -kShift), rate, odmf, options);
    out.offsets.push_back(sensor);
    const double c =
        (weighted_rss(plus) + weighted_rss(minus) - 2.0 * rss) / (2.0 * kShift * kShift);
    const double b = (weighted_rss(plus) - weighted_rss(minus)) / (2.0 * kShift);
    const Eigen::VectorXd slope =
        (plus.estimate.value.head(n) - minus.estimate.value.head(n)) / (2.0 * kShift);
    if (!(c * kShift * kShift > kUnseen * rss) || !(dof > 0.0)) {
      for (Eigen::Index i = 0; i < n; ++i)
        if (!(std::abs(slope(i)) * kShift <= kMoves * std::sqrt(variance(i))))
          compared[static_cast<std::size_t>(i)] = false;
      continue;
    }
    const double offset = -b / (2.0 * c);
    const double offset_variance = (rss - b * b / (4.0 * c)) / dof / c;
    value += slope * offset;
    variance += slope.array().square().matrix() * offset_variance;
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const model::ParameterInfo& info = declared_fit.parameters[static_cast<std::size_t>(i)];
    if (!compared[static_cast<std::size_t>(i)]) {
      out.not_compared.push_back(info.name);
      continue;
    }
    if (!std::isfinite(value(i)) || !std::isfinite(published.value(i)) ||
        !std::isfinite(published.std(i)))
      continue;
    // Hausman's comparison with the published value as "before" and the sharper value "after".
    ParameterChange change{info.name,        info.unit, published.value(i),
                           published.std(i), value(i),  std::sqrt(variance(i)),
                           std::nullopt};
    const double moved = hausman_distance(change, /*sharpens=*/true);
    out.compared.push_back({info.name, info.unit, published.value(i), published.std(i), value(i),
                            std::sqrt(variance(i)), std::isnan(moved) ? 0.0 : moved});
  }
  if (!out.compared.empty()) out.bound = hausman_bound(out.compared.size());
  return out;
}

}  // namespace dynid::residual
