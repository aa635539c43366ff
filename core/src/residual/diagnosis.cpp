#include "dynid/residual/diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include <boost/math/distributions/normal.hpp>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"
#include "dynid/residual/varying_parameter.hpp"

namespace dynid::residual {
namespace {

// A channel's values at the residual's rows delayed by `lag` grid samples (NaN where the
// delayed sample falls outside the row's segment).
class ChannelAtRows {
 public:
  ChannelAtRows(const std::vector<ingest::PreprocessedSegment>& run, const std::vector<Eigen::Index>& grid)
      : run_(run), grid_(grid) {
    for (Eigen::Index g : grid) {
      std::size_t s = 0;
      while (s < run.size() && !(g >= run[s].first && g < run[s].first + run[s].channels.samples())) ++s;
      segment_.push_back(s);
    }
  }
  Eigen::VectorXd values(const std::string& channel, Eigen::Index lag) const {
    Eigen::VectorXd out(static_cast<Eigen::Index>(grid_.size()));
    for (std::size_t i = 0; i < grid_.size(); ++i) {
      out(static_cast<Eigen::Index>(i)) = std::numeric_limits<double>::quiet_NaN();
      if (segment_[i] >= run_.size()) continue;
      const ingest::PreprocessedSegment& seg = run_[segment_[i]];
      const Eigen::Index k = grid_[i] - lag - seg.first;
      if (k >= 0 && k < seg.channels.samples() && seg.channels.valid(k))
        out(static_cast<Eigen::Index>(i)) = seg.channels[channel](k);
    }
    return out;
  }

 private:
  const std::vector<ingest::PreprocessedSegment>& run_;
  const std::vector<Eigen::Index>& grid_;
  std::vector<std::size_t> segment_;
};

// Autocorrelation of x (demeaned, NaN-free) at lags 1..max between rows one decimation step
// apart, by grid distance.
std::vector<double> autocorrelation(const Eigen::VectorXd& x, const std::vector<Eigen::Index>& grid, int odmf,
                                    int max) {
  std::vector<double> out(static_cast<std::size_t>(max + 1), 0.0);
  const double ss = x.squaredNorm();
  if (ss <= 0.0) return out;
  for (std::size_t i = 0; i < grid.size(); ++i)
    for (std::size_t j = i; j-- > 0;) {
      const Eigen::Index lag = (grid[i] - grid[j]) / odmf;
      if (lag > max) break;
      out[static_cast<std::size_t>(lag)] += x(static_cast<Eigen::Index>(i)) * x(static_cast<Eigen::Index>(j));
    }
  for (double& v : out) v /= ss;
  return out;
}

Eigen::VectorXd demeaned(Eigen::VectorXd x) {
  x.array() -= x.mean();
  return x;
}

// The correlation of r with u over the rows where u is defined; n is that count.
double correlation(const Eigen::VectorXd& r, const Eigen::VectorXd& u, Eigen::Index& n) {
  double mr = 0.0, mu = 0.0;
  n = 0;
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (std::isfinite(u(i))) mr += r(i), mu += u(i), ++n;
  if (n < 3) return 0.0;
  mr /= static_cast<double>(n);
  mu /= static_cast<double>(n);
  double ru = 0.0, rr = 0.0, uu = 0.0;
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (std::isfinite(u(i))) {
      ru += (r(i) - mr) * (u(i) - mu);
      rr += (r(i) - mr) * (r(i) - mr);
      uu += (u(i) - mu) * (u(i) - mu);
    }
  return rr > 0.0 && uu > 0.0 ? ru / std::sqrt(rr * uu) : 0.0;
}

struct SignatureInputs {
  const model::Model& model;
  const std::vector<ingest::PreprocessedSegment>& run;
  const ModelFit& fit;
  const NoiseFloor& floor;
  double rate;
  int odmf;
  double block_seconds;
};

std::vector<std::string> signature_channels(const SignatureInputs& in) {
  std::vector<std::string> out;
  const std::vector<std::string> measured = in.model.measured_side();
  for (const std::string& name : in.run.front().channels.names()) {
    const std::string base = name.rfind("d_", 0) == 0 ? name.substr(2) : name;
    if (std::find(measured.begin(), measured.end(), base) == measured.end()) out.push_back(name);
  }
  return out;
}

constexpr std::size_t kPlottedCurves = 4;  // per group, in Signature::curves

// The group's curves, strongest (peak |c| / bound) first, kPlottedCurves at most.
void keep_strongest(std::vector<CorrelationCurve>& group_curves, std::vector<CorrelationCurve>& out) {
  std::sort(group_curves.begin(), group_curves.end(), [](const auto& a, const auto& b) { return a.peak > b.peak; });
  if (group_curves.size() > kPlottedCurves) group_curves.resize(kPlottedCurves);
  out.insert(out.end(), group_curves.begin(), group_curves.end());
}

void add_correlations(const SignatureInputs& in, const ResidualSeries& s, double error_rate, double max_lag_s,
                      std::vector<CorrelationFinding>& found, std::vector<CorrelationCurve>& curves) {
  std::vector<Eigen::Index> grid;
  for (double t : s.time_s) grid.push_back(static_cast<Eigen::Index>(std::llround(t * in.rate)));
  const ChannelAtRows at(in.run, grid);
  const Eigen::VectorXd r = demeaned(s.residual);
  const int lags = std::max(0, static_cast<int>(std::floor(max_lag_s * in.rate / in.odmf)));
  const std::vector<double> rho_r = autocorrelation(r, grid, in.odmf, lags);
  const std::vector<std::string> channels = signature_channels(in);
  const double tests = static_cast<double>(channels.size() * static_cast<std::size_t>(2 * lags + 1) + 1) *
                       static_cast<double>(in.fit.groups.size());
  const double z = boost::math::quantile(boost::math::normal(), 1.0 - error_rate / (2.0 * tests));
  std::vector<CorrelationCurve> group_curves;
  auto test = [&](const std::string& name, const std::vector<double>& rho_u, Eigen::Index lag,
                  const Eigen::VectorXd& u, CorrelationCurve* curve) {
    Eigen::Index n = 0;
    const double c = correlation(r, u, n);
    double sum = 0.0;
    for (std::size_t j = 1; j < rho_u.size() && j < rho_r.size(); ++j) sum += rho_r[j] * rho_u[j];
    const double bound = z * std::sqrt(std::max(1.0, 1.0 + 2.0 * sum) / static_cast<double>(std::max<Eigen::Index>(n, 1)));
    if (std::abs(c) > bound)
      found.push_back({s.group, name, static_cast<double>(lag) / in.rate, c, bound});
    if (curve != nullptr) {
      curve->lag_s.push_back(static_cast<double>(lag) / in.rate);
      curve->correlation.push_back(c);
      curve->bound.push_back(bound);
      curve->peak = std::max(curve->peak, std::abs(c) / bound);
    }
  };
  for (const std::string& name : channels) {
    const Eigen::VectorXd u0 = at.values(name, 0);
    if (!u0.allFinite() || (u0.array() - u0.mean()).matrix().squaredNorm() <= 0.0) continue;
    const std::vector<double> rho_u = autocorrelation(demeaned(u0), grid, in.odmf, lags);
    CorrelationCurve curve{s.group, name, {}, {}, {}};
    for (int k = -lags; k <= lags; ++k) {
      const Eigen::Index lag = static_cast<Eigen::Index>(k) * in.odmf;
      test(name, rho_u, lag, k == 0 ? u0 : at.values(name, lag), &curve);
    }
    group_curves.push_back(std::move(curve));
  }
  keep_strongest(group_curves, curves);
  Eigen::VectorXd time(static_cast<Eigen::Index>(s.time_s.size()));
  for (std::size_t i = 0; i < s.time_s.size(); ++i) time(static_cast<Eigen::Index>(i)) = s.time_s[i];
  if (time.size() > 2) test("time", autocorrelation(demeaned(time), grid, in.odmf, lags), 0, time, nullptr);
}

void locate_span(const SignatureInputs& in, const ResidualSeries& s, double floor_rms, Signature& out) {
  if (!(floor_rms > 0.0) || s.time_s.empty()) return;
  std::map<long, std::pair<double, long>> blocks;
  for (std::size_t i = 0; i < s.time_s.size(); ++i) {
    auto& b = blocks[static_cast<long>(std::floor(s.time_s[i] / in.block_seconds))];
    b.first += s.residual(static_cast<Eigen::Index>(i)) * s.residual(static_cast<Eigen::Index>(i));
    ++b.second;
  }
  for (const auto& [block, sums] : blocks) {
    const double ratio = std::sqrt(sums.first / static_cast<double>(sums.second)) / floor_rms;
    if (ratio > out.span_ratio) {
      out.span_ratio = ratio;
      out.span_group = s.group;
      out.span_start_s = static_cast<double>(block) * in.block_seconds;
      out.span_end_s = out.span_start_s + in.block_seconds;
    }
  }
}

double peak_frequency(const Spectrum& spectrum) {
  double best = 0.0;
  double frequency = 0.0;
  for (Eigen::Index i = 1; i < spectrum.amplitude.size(); ++i)
    if (spectrum.amplitude(i) > best) best = spectrum.amplitude(i), frequency = spectrum.frequency_hz(i);
  return frequency;
}

Signature signature_of(const SignatureInputs& in, const DiagnosisOptions& options) {
  Signature out;
  for (const ResidualSeries& s : in.fit.series) {
    add_correlations(in, s, options.error_rate, options.max_lag_s, out.correlations, out.curves);
    const auto g = std::find_if(in.floor.groups.begin(), in.floor.groups.end(),
                                [&](const GroupFloor& f) { return f.group == s.group; });
    if (g != in.floor.groups.end()) locate_span(in, s, g->floor_rms, out);
  }
  std::sort(out.correlations.begin(), out.correlations.end(), [](const auto& a, const auto& b) {
    return std::abs(a.correlation) / a.bound > std::abs(b.correlation) / b.bound;
  });
  // One line per channel and group: its strongest lag.
  std::vector<CorrelationFinding> kept;
  for (const CorrelationFinding& f : out.correlations) {
    const bool seen = std::any_of(kept.begin(), kept.end(), [&](const CorrelationFinding& k) {
      return k.channel == f.channel && k.group == f.group;
    });
    if (!seen && kept.size() < 8) kept.push_back(f);
  }
  out.correlations = std::move(kept);
  if (!in.fit.series.empty()) out.peak_frequency_hz = peak_frequency(in.fit.series.front().spectrum);
  return out;
}

SignatureInputs signature_inputs(const model::Model& model, const std::vector<ingest::PreprocessedSegment>& segments,
                                 const Diagnosis& d, double rate, int odmf, const DiagnosisOptions& options) {
  return {model, segments, d.screen.fit, d.floor, rate, odmf, options.screen.fit.cross_validation.block_seconds};
}

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, pattern, a, b, c);
  return buf;
}

// The lowest ratio of squares (residual / floor) a model that lacks nothing reaches, per group,
// at level kBelowFloorErrorRate: a candidate that explains a real effect must not be refused
// by chance often, so this side is stricter than the floor test (measured: at 5 % the drift that
// explained a drifting offset exactly was refused, after-ratio 0.76 against 0.77). Better sensors
// leave far less: the accelerometer for a noisy wheel-speed derivative, 0.1 to 0.3.
constexpr double kBelowFloorErrorRate = 0.001;

double lowest_ratio(const GroupFloor& g, std::size_t groups) {
  const double z = boost::math::quantile(boost::math::normal(), 1.0 - kBelowFloorErrorRate / static_cast<double>(groups));
  return std::exp(-z * g.log_ratio_std);
}

// The sensors a candidate reads beyond the model's own columns: a physical effect's channels, a
// dictionary term's, a delay's or an offset's channel.
std::vector<std::string> sensors_of(const CandidateScore& c, const std::vector<model::Effect>& effects) {
  for (const model::Effect& e : effects)
    if (e.name == c.effect) return e.channels;
  if (model::is_dictionary_effect(c.effect)) return model::dictionary_effect(c.effect, {"model"}).channels;
  if (c.effect.rfind("delay:", 0) == 0 || c.effect.rfind("offset:", 0) == 0) {  // <kind>:<channel>@<value>
    const std::string channel = c.effect.substr(c.effect.find(':') + 1);
    return {channel.substr(0, channel.find('@'))};
  }
  return {};
}

// Why `c` is implausible before any fit of its own: the omitted-variable identity (CandidateScore::
// alias) gives the declared parameters with it, x_with = x_without - alias c, and their std,
// sqrt(std_without^2 + alias^2 std_c^2) (the restricted estimate and the added coefficient are
// uncorrelated); the candidate's own coefficient is held to its effect's bounds. Empty when
// nothing leaves its bounds, or for a candidate of several columns (the trace checks every
// candidate it adds on its own fit: trace.cpp).
std::string bounds_refusal(const CandidateScore& c, const ModelFit& fit, const std::vector<model::Effect>& effects) {
  if (c.alias.size() != fit.parameters.size() || !std::isfinite(c.coefficient)) return {};
  for (std::size_t j = 0; j < fit.parameters.size(); ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    const double with = fit.estimate.value(i) - c.alias[j] * c.coefficient;
    const double std = std::hypot(fit.estimate.standard_deviation(i), c.alias[j] * c.coefficient_std);
    if (std::string why = out_of_bounds(fit.parameters[j], with, std); !why.empty()) return "it takes " + why;
  }
  for (const model::Effect& e : effects)
    if (e.name == c.effect && e.parameters.size() == 1)
      if (std::string why = out_of_bounds(e.parameters.front(), c.coefficient, c.coefficient_std); !why.empty())
        return "its own coefficient " + why;
  return {};
}

// What the floor of a candidate's model needs.
struct FloorInputs {
  const model::Model& model;
  const std::vector<std::string>& declared;
  const ingest::RecordedRun& run;
  const std::vector<ingest::PreprocessedSegment>& segments;
  const std::vector<ChannelNoise>& noise;
  const NoiseFloorOptions& options;
  FloorCache& cache;
};

// What a significant candidate's own model says: whether it leaves the residual under the
// floor of that model (it fits noise), and whether that floor is lower than the declared one
// (it reads a better sensor of a declared signal: the accelerometer for the differentiated
// wheel speed), each at kBelowFloorErrorRate.
struct OwnFloor {
  std::string below;    ///< why it fits noise; empty when it does not
  bool lowers = false;  ///< its floor is significantly under the declared one
  GroupFloor worst;     ///< the group furthest above its floor (ratio / upper_ratio)
  /// What it removes, and (`reaches`) whether its model's residual passes that model's floor
  /// test (the same test, at the same level, as the declared model's): the candidate explains
  /// the whole residual, not a part of it.
  Materiality materiality;
  bool reaches() const { return materiality.reaches; }
};

OwnFloor own_floor(const CandidateScore& c, const FloorInputs& in, const NoiseFloor& declared) {
  std::vector<std::string> effects = in.declared;
  effects.push_back(c.effect);
  NoiseFloor floor;
  try {
    floor = noise_floor(in.model, effects, in.run, in.segments, in.noise, in.options, in.cache);
  } catch (const InputError&) {
    // The extended model's floor cannot be computed: judged as the declared floor's missing
    // effect, one that explains the whole residual.
    OwnFloor unknown;
    unknown.materiality.reaches = true;
    return unknown;
  }
  OwnFloor out;
  out.materiality = materiality(declared, floor);
  for (const GroupFloor& f : floor.groups)
    if (f.rows > 0 && (out.worst.rows == 0 || f.ratio / f.upper_ratio > out.worst.ratio / out.worst.upper_ratio))
      out.worst = f;
  const double z = boost::math::quantile(boost::math::normal(), 1.0 - kBelowFloorErrorRate / static_cast<double>(floor.groups.size()));
  for (std::size_t g = 0; g < floor.groups.size(); ++g) {
    const GroupFloor& f = floor.groups[g];
    if (f.rows == 0) continue;
    if (out.below.empty() && f.ratio < lowest_ratio(f, floor.groups.size()))
      out.below = "takes the " + f.group + " residual below the noise floor of the model it makes" +
                  format(" (ratio of squares %.2g, at least %.2g expected)", f.ratio, lowest_ratio(f, floor.groups.size())) +
                  ": it fits the noise of a declared signal (a better sensor of it), not a missing effect";
    if (g < declared.groups.size() && declared.groups[g].floor_rms > 0.0 && f.floor_rms > 0.0) {
      const GroupFloor& d = declared.groups[g];
      const double sd = std::hypot(f.floor_relative_std, d.floor_relative_std);
      out.lowers = out.lowers || 2.0 * std::log(f.floor_rms / d.floor_rms) < -z * sd;
    }
  }
  return out;
}

// Materiality: with thousands of rows a HAC Wald test finds structure far smaller than anything
// that matters (measured on an independent car's clean steering runs: a yaw-rate "delay" of
// 0 ms and derivative terms at p < 1e-5, each removing 0.00-0.05 of the yaw residual's ratio of
// squares to its floor; a trace that added four such terms moved the front cornering stiffness by
// 41 %). A missing effect
// other than a better sensor is a finding only when it explains the excess the floor test found
// (its model reaches its own floor) or removes, in some group, at least the smallest excess that
// test resolves: upper_ratio - 1 of the declared floor's mean square (0.19-0.26 on runs of 1-3
// minutes). Smaller structure is within what the floor itself can tell from noise (its measured
// channel noise is uncertain by as much), so it can be neither the explanation nor an added term:
// it is listed as refused, with its size. A better sensor is judged by Hausman's test instead
// (trace.hpp): the mean square it removes is mostly the declared signal's noise.
std::string immaterial_text(const CandidateScore& c, const Materiality& m) {
  return "significant (HAC Wald p = " + format("%.2g", c.p_value) +
         ") but immaterial: it removes " + format("%.3g", m.removed) + " of the " + m.group +
         " residual's mean square in units of the floor's, less than the " +
         format("%.3g", m.resolution) +
         " the floor test resolves, and does not take the residual to the floor";
}

// Among the significant candidates, those that leave the residual under the floor of the model
// they make are refused, and with them every candidate that reads the same sensor (a lag of the
// accelerometer is the accelerometer, a little worse: measured on bench/trace, it won every run
// with vx late). Of the rest, a missing effect (its model's floor is the declared one's) goes
// before a better sensor of a declared signal (its floor is lower): both can explain a grade,
// but the accelerometer also replaces the noisy wheel-speed derivative, wins on held-out error
// by that alone, and biases the drag terms (our own simulator's hill run: SCx +19 % with it,
// -5 % with the GNSS grade; bench/trace: it also beat a vx delay and a mass step). The
// one-standard-error rule then picks within the chosen group.
//
// The accepted candidate explains the residual when the model it makes passes the floor test;
// when its residual stays above that model's floor it explains a part only (Diagnosis::partial):
// the verdict is then "structure left", with the candidate named as the part it explains. A
// missing effect that explains the whole residual (its model passes the floor test) goes before
// one that explains a part, however much more of the rows' noise-dominated mean square the
// latter takes: the floor test is the criterion of adequacy, the held-out error a ranking (with
// the block tests in the verdict, tried: a head wind's slow residual was taken to the floor by
// linear_drag, -1.6 % held out, and left above it by a lag of the accelerometer, -10 %). The
// floor test's level is the chance that a candidate that explains everything is called partial
// (NoiseFloorOptions::error_rate, 0.025); measured on bench/trace, every effect no family expresses (tyre relaxation, backlash,
// gusts) left its best candidate's model 1.3 to 4 times above its floor.
//
// At the declared floor (`at_floor`), only better sensors are weighed, each sensor through the
// first candidate that reads it: a missing effect read through the declared sensors shares
// their floor and cannot show what their noise hides.
void accept_best(Diagnosis& d, const FloorInputs& in, bool at_floor = false,
                 std::string* passed_over = nullptr) {
  const std::vector<model::Effect> effects = in.model.candidate_effects();
  std::vector<std::string> refused_sensors, judged_sensors;
  std::vector<CandidateScore> missing, partial, sensors_better;
  std::map<std::string, OwnFloor> floors;
  for (const CandidateScore& c : d.screen.candidates) {
    if (!c.significant) break;  // ranked: the significant ones come first
    // Past the first missing effect that explains the whole residual, only an earlier kind can
    // move ahead of it (the one-error rule): the others need no floor of their own.
    if (!at_floor && !missing.empty() && static_cast<int>(c.kind) >= static_cast<int>(missing.front().kind)) continue;
    const std::vector<std::string> sensors = sensors_of(c, effects);
    if (at_floor) {
      // A sensor is judged by its best use, the first candidate in the ranking that reads it
      // (the accelerometer, not its lag, which leaves structure of its own).
      if (sensors.empty() || std::find_first_of(sensors.begin(), sensors.end(), judged_sensors.begin(),
                                                judged_sensors.end()) != sensors.end())
        continue;
      judged_sensors.insert(judged_sensors.end(), sensors.begin(), sensors.end());
    }
    const auto same = std::find_first_of(sensors.begin(), sensors.end(), refused_sensors.begin(), refused_sensors.end());
    if (same != sensors.end()) {
      d.refused.push_back({c.effect, "reads " + *same + ", the sensor refused above as a better sensor of a declared signal"});
      continue;
    }
    if (std::string why = bounds_refusal(c, d.screen.fit, effects); !why.empty()) {
      d.refused.push_back({c.effect, why});
      continue;
    }
    const OwnFloor own = own_floor(c, in, d.floor);
    if (!own.below.empty()) {
      d.refused.push_back({c.effect, own.below});
      refused_sensors.insert(refused_sensors.end(), sensors.begin(), sensors.end());
      continue;
    }
    if (!own.lowers && !own.materiality.material()) {
      d.refused.push_back({c.effect, immaterial_text(c, own.materiality)});
      continue;
    }
    (own.lowers ? sensors_better : own.reaches() ? missing : partial).push_back(c);
    floors.emplace(c.effect, own);
  }
  if (at_floor) missing.clear(), partial.clear();
  std::vector<CandidateScore> sensors_reaching;
  for (const CandidateScore& c : sensors_better)
    if (floors.at(c.effect).reaches()) sensors_reaching.push_back(c);
  std::vector<CandidateScore>& chosen = !missing.empty()          ? missing
                                        : !sensors_reaching.empty() ? sensors_reaching
                                        : !partial.empty()          ? partial
                                                                    : sensors_better;
  if (chosen.empty()) return;
  prefer_simplest_within_one_error(chosen);
  d.accepted = chosen.front();
  const OwnFloor& own = floors.at(d.accepted->effect);
  if (!own.reaches()) d.partial = own.worst;
  d.better_sensor = own.lowers;
  if ((&chosen == &missing || &chosen == &partial) && passed_over != nullptr &&
      !sensors_better.empty())
    *passed_over = sensors_better.front().effect;
  if (&chosen == &missing || &chosen == &partial)
    for (const CandidateScore& c : sensors_better)
      d.refused.push_back({c.effect, "passed over for " + d.accepted->effect +
                                         ": it lowers the noise floor (a better sensor of a declared signal), " +
                                         d.accepted->effect + " explains the residual as a missing effect"});
}

// A parameter's time course judged on the sharpest rows. When the accepted missing effect is a
// varying parameter (a step or a drift of P) and a better sensor of a declared signal was passed
// over for it, whether P steps or drifts, and when, is chosen again on the rows of the model with
// that sensor declared: the screen of P's varying candidates (each step located as usual) on
// those rows. Why: least squares' bias from noise in a regressor (errors in variables: d_vx
// differentiated from the wheel speeds) depends on how the run excites the parameter, so it
// differs between the run's phases, and on the noisy rows a parameter seems to change where the
// phase changes. Measured on an independently written car (docs/results/RESIDUAL.md): clean runs
// gave least-squares mass steps of -21 kg and -226 kg at drive/coast boundaries, and a load taken
// off at a stop (95.7 s) was located at the shift to neutral 60 s earlier (residual RMS 100.4
// against 103.9 N at the stop), while the same model with the accelerometer in d_vx's place fitted
// the stop better (26.7 against 27.7 N) and located the step there. The choice made on the sharper
// rows is accepted when it keeps the parameters within their bounds there, is material and does
// not fit the declared signals' noise on the declared rows (its own floor, as any candidate);
// else the first choice stands.
void time_course_on_sharper_rows(Diagnosis& d, const FloorInputs& in, const std::string& sensor,
                                 const ScreenOptions& screen, double rate, int odmf) {
  if (!is_varying_effect(d.accepted->effect)) return;
  const std::string parameter = parse_varying_effect(d.accepted->effect, in.model).parameter;
  ScreenOptions options = screen;
  for (const CandidateScore& c : d.screen.candidates)
    if (c.evaluated && c.kind == CandidateKind::kVarying && is_varying_effect(c.effect) &&
        parse_varying_effect(c.effect, in.model).parameter == parameter)
      options.only.push_back(c.effect);
  if (options.only.empty()) return;  // an empty list would test every candidate
  std::vector<std::string> sharper = in.declared;
  sharper.push_back(sensor);
  ScreenResult again;
  try {
    again = screen_effects(in.model, sharper, in.segments, rate, odmf, options);
  } catch (const InputError&) {
    return;  // the sharper model cannot be built on this run: the first choice stands
  }
  const CandidateScore* best = again.best();
  if (best == nullptr || best->effect == d.accepted->effect) return;
  if (!bounds_refusal(*best, again.fit, in.model.candidate_effects()).empty()) return;
  const OwnFloor own = own_floor(*best, in, d.floor);
  if (!own.below.empty() || (!own.lowers && !own.materiality.material())) return;
  CandidateScore chosen = *best;
  chosen.finding += std::string(chosen.finding.empty() ? "" : "; ") + "judged with " + sensor +
                    " declared (a better sensor of a declared signal, whose rows carry less of its "
                    "noise): these figures are that model's";
  // Its aliases are on that model's columns, not the declared ones (separability.hpp reads them
  // against the declared fit): left out.
  chosen.alias.clear();
  d.refused.push_back(
      {d.accepted->effect, "its parameter's time course is judged on the rows with " + sensor +
                               " declared, where the best of " + parameter +
                               "'s steps and drifts is " + chosen.effect});
  // Listed among the candidates, before the one it replaces, with the figures of the rows it
  // was judged on (its finding says which).
  auto first =
      std::find_if(d.screen.candidates.begin(), d.screen.candidates.end(),
                   [&](const CandidateScore& c) { return c.effect == d.accepted->effect; });
  d.screen.candidates.insert(first, chosen);
  d.accepted = std::move(chosen);
  d.partial.reset();
  if (!own.reaches()) d.partial = own.worst;
}

// Above the declared floor, a better sensor is judged by the parameters, not by the mean square
// it removes (most of that is the declared signal's error): against the published values, its
// offsets nuisances (sensor_agreement.hpp). Where it agrees, it is no missing effect and is not
// added; where it differs, or that cannot be told, it stays the accepted candidate.
void judge_better_sensor(Diagnosis& d, const FloorInputs& in, double rate, int odmf) {
  SensorAgreement agreement;
  try {
    agreement = sensor_agreement(in.model, in.declared, d.accepted->effect,
                                 sensors_of(*d.accepted, in.model.candidate_effects()), in.segments,
                                 rate, odmf, in.options.fit, in.run.announcement.preprocessing);
  } catch (const InputError&) {
    return;
  }
  if (!agreement.agrees()) return;
  d.sensor_reaches = !d.partial;
  std::string why =
      "a better sensor of a declared signal, not a missing effect: " + agreement.statement();
  if (d.partial)
    why += "; its model leaves the " + d.partial->group +
           format(" residual above its own floor (ratio of squares %.3g, at the floor up to %.3g)",
                  d.partial->ratio, d.partial->upper_ratio);
  d.refused.insert(d.refused.begin(), {d.accepted->effect, why});
  d.sensor_error = std::move(agreement);
  d.accepted.reset();
  d.partial.reset();
  d.better_sensor = false;
}

}  // namespace

Materiality materiality(const NoiseFloor& declared, const NoiseFloor& extended) {
  Materiality out;
  out.reaches = extended.adequate();
  for (std::size_t g = 0; g < extended.groups.size() && g < declared.groups.size(); ++g) {
    const GroupFloor& d = declared.groups[g];
    const GroupFloor& f = extended.groups[g];
    if (d.rows == 0 || !(d.floor_rms > 0.0)) continue;
    const double removed = (d.residual_rms * d.residual_rms - f.residual_rms * f.residual_rms) /
                           (d.floor_rms * d.floor_rms);
    const double resolution = d.upper_ratio - 1.0;
    // The group where it removes most against what the test resolves there.
    if (out.group.empty() || removed * out.resolution > out.removed * resolution)
      out.group = d.group, out.removed = removed, out.resolution = resolution;
  }
  return out;
}

HiddenStructure hidden_structure(const std::string& sensor, const NoiseFloor& declared,
                                 const GroupFloor& extended) {
  HiddenStructure out{sensor, extended.group, extended.residual_rms, extended.floor_rms, 0.0, 0.0};
  const auto d = std::find_if(declared.groups.begin(), declared.groups.end(),
                              [&](const GroupFloor& g) { return g.group == extended.group; });
  // Without the declared group's floor nothing bounds it: material, the verdict says it.
  if (d == declared.groups.end() || !(d->floor_rms > 0.0)) {
    out.share = std::numeric_limits<double>::infinity();
    return out;
  }
  out.share =
      (extended.residual_rms * extended.residual_rms - extended.floor_rms * extended.floor_rms) /
      (d->floor_rms * d->floor_rms);
  out.resolution = d->upper_ratio - 1.0;
  return out;
}

std::string HiddenStructure::statement() const {
  char buf[400];
  std::snprintf(
      buf, sizeof buf,
      "with %s (a better sensor of a declared signal) the %s residual shows structure the declared "
      "signals' noise hides: RMS %.4g against that model's floor %.4g, %.3g of the declared "
      "floor's mean "
      "square, %s the %.3g the floor test resolves",
      sensor.c_str(), group.c_str(), residual_rms, floor_rms, share,
      material() ? "at least" : "less than", resolution);
  return std::string(buf) + (material()
                                 ? ""
                                 : ": immaterial by that measure, a note (no candidate expresses "
                                   "it, so nothing says which parameter it would move)");
}

const char* verdict_name(Verdict verdict) {
  switch (verdict) {
    case Verdict::kAdequate: return "adequate";
    case Verdict::kExplained: return "explained";
    case Verdict::kStructureLeft: return "structure left";
  }
  return "?";
}

namespace {

std::string implausible_text(const std::vector<std::string>& implausible) {
  std::string out;
  for (const std::string& i : implausible) out += (out.empty() ? "" : "; ") + i;
  return out.empty() ? out : "; the model as declared is implausible on this run: " + out;
}

// The groups whose residual is above the floor at a longer time scale (noise_floor.hpp, 4.),
// each at the scale furthest above it: evidence beside the verdict.
std::string slow_structure_text(const NoiseFloor& floor) {
  std::string out;
  for (const GroupFloor& g : floor.groups)
    if (const ScaleFloor* s = g.worst_scale())
      out += (out.empty() ? "" : ", ") + g.group +
             format(" over blocks of %.2g s (slower than about %.2g Hz): ratio %.3g", s->block_seconds,
                    1.0 / (2.0 * s->block_seconds), s->ratio) +
             format(", at the floor up to %.3g", s->upper_ratio);
  return out.empty() ? out : "; slow structure beside the verdict (the rows' test decides): " + out;
}

}  // namespace

std::string Diagnosis::statement() const {
  return verdict_statement() + slow_structure_text(floor) + implausible_text(implausible);
}

std::string Diagnosis::verdict_statement() const {
  std::string floors;
  for (const GroupFloor& g : floor.groups)
    if (g.rows > 0)
      floors += (floors.empty() ? "" : "; ") + g.group +
                format(" residual RMS %.4g, noise floor %.4g (ratio of squares %.3g", g.residual_rms, g.floor_rms,
                       g.ratio) +
                format(", at the floor up to %.3g)", g.upper_ratio);
  std::string out;
  switch (verdict) {
    case Verdict::kAdequate: {
      if (sensor_error)
        return "adequate: the residual of " + screen.fit.model + " is above the noise floor (" +
               floors + ") by an error of a declared signal, not a missing effect: " +
               sensor_error->statement() + ", and its model reaches its own floor";
      out = "adequate: the residual of " + screen.fit.model + " is at the noise floor (" + floors + ")";
      if (hidden) out += "; note: " + hidden->statement();
      if (const CandidateScore* b = screen.best())
        out += "; " + b->effect +
               " is significant all the same: at the floor it can only be fitting the regressors' noise "
               "(a better sensor of a declared signal) or a structure smaller than the noise, not a "
               "missing effect";
      return out;
    }
    case Verdict::kExplained:
      return "explained: above the noise floor (" + floors + "); " + accepted->effect + " (" +
             kind_name(accepted->kind) + (accepted->finding.empty() ? "" : ": " + accepted->finding) +
             ") explains it: held-out RMS " +
             format("%+.1f %%", -100.0 * accepted->held_out_drop) +
             format(", HAC Wald p = %.2g < %.2g", accepted->p_value, screen.level);
    case Verdict::kStructureLeft:
      break;
  }
  out = masked ? "structure left under the declared signals' noise: the residual is at the noise floor (" + floors +
                    "), but with " + accepted->effect + " the model's own, lower floor shows what that noise hid"
               : "structure left that no candidate explains: above the noise floor (" + floors + ")";
  if (accepted && partial)
    out += "; " + accepted->effect + " (" + kind_name(accepted->kind) +
           (accepted->finding.empty() ? "" : ": " + accepted->finding) + ") explains a part of it: held-out RMS " +
           format("%+.1f %%", -100.0 * accepted->held_out_drop) +
           format(", HAC Wald p = %.2g < %.2g", accepted->p_value, screen.level) + ", but with it the " +
           partial->group + format(" residual stays above its own noise floor (ratio of squares %.3g, at the floor up to %.3g)",
                                   partial->ratio, partial->upper_ratio);
  for (const RefusedCandidate& r : refused) out += "; " + r.effect + " refused: " + r.reason;
  if (!signature.correlations.empty()) {
    const CorrelationFinding& f = signature.correlations.front();
    out += "; the residual correlates with " + f.channel + format(" at lag %+.0f ms (r = %.2f, bound %.2f)", 1000.0 * f.lag_s, f.correlation, f.bound);
  }
  if (signature.span_ratio > 0.0)
    out += format("; most of it in %.0f-%.0f s (RMS %.2g times the floor)", signature.span_start_s,
                  signature.span_end_s, signature.span_ratio);
  if (signature.peak_frequency_hz > 0.0) out += format("; spectrum peak at %.2f Hz", signature.peak_frequency_hz);
  return out;
}

std::string out_of_bounds(const model::ParameterInfo& info, double value, double std) {
  const double margin = 2.0 * (std::isfinite(std) ? std : 0.0);
  if (!std::isfinite(value) || info.within_bounds(value - margin) || info.within_bounds(value + margin)) return {};
  return info.name + format(" = %.4g +- %.2g ", value, std) + info.unit + ", outside its physical bounds (" +
         info.bounds_text() + ") by more than two standard deviations";
}

Diagnosis diagnose(const model::Model& model, const std::vector<std::string>& declared,
                   const ingest::RecordedRun& run, const DiagnosisOptions& options) {
  return diagnose(model, declared, run, ingest::preprocess_offline(run), options);
}

Diagnosis diagnose(const model::Model& model, const std::vector<std::string>& declared,
                   const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                   const DiagnosisOptions& options) {
  FloorCache cache(run, segments);
  return diagnose(model, declared, run, segments, options, cache);
}

Diagnosis diagnose(const model::Model& model, const std::vector<std::string>& declared,
                   const ingest::RecordedRun& run,
                   const std::vector<ingest::PreprocessedSegment>& segments,
                   const DiagnosisOptions& options, FloorCache& cache) {
  if (segments.empty()) throw InputError("residual analysis of " + model.name() + ": the run has no valid segment");
  const double rate = run.announcement.sample_rate_hz;
  const int odmf = run.announcement.preprocessing.odmf;
  Diagnosis d;
  d.screen = screen_effects(model, declared, segments, rate, odmf, options.screen);
  const ls::Estimate& fit = d.screen.fit.estimate;
  for (std::size_t j = 0; j < d.screen.fit.parameters.size(); ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    if (std::string why = out_of_bounds(d.screen.fit.parameters[j], fit.value(i), fit.standard_deviation(i)); !why.empty())
      d.implausible.push_back(std::move(why));
  }
  NoiseFloorOptions floor_options = options.floor;
  floor_options.fit = options.screen.fit;
  const std::vector<ChannelNoise>& noise = cache.channel_noise(options.declared_noise);
  d.floor = noise_floor(model, declared, run, segments, noise, floor_options, cache);
  const FloorInputs floor_inputs{model, declared, run, segments, noise, floor_options, cache};
  if (d.floor.adequate()) {
    // Structure hidden under the declared signals' noise (diagnosis.hpp): the candidate the loop
    // would accept, when its model stays above its own floor.
    Diagnosis probe = d;
    accept_best(probe, floor_inputs, /*at_floor=*/true);
    if (probe.accepted && probe.partial)
      if (HiddenStructure hidden =
              hidden_structure(probe.accepted->effect, d.floor, *probe.partial);
          !hidden.material())
        d.hidden = std::move(hidden);
    if (!(probe.accepted && probe.partial) || d.hidden) {
      d.verdict = Verdict::kAdequate;
      d.inseparable = inseparable_effects(model, d.screen);
      d.signature = signature_of(signature_inputs(model, segments, d, rate, odmf, options), options);
      return d;
    }
    d.accepted = std::move(probe.accepted);
    d.partial = std::move(probe.partial);
    d.better_sensor = probe.better_sensor;
    d.refused = std::move(probe.refused);
    d.masked = true;
  } else {
    std::string passed_over;
    accept_best(d, floor_inputs, false, &passed_over);
    if (d.accepted && !d.better_sensor && !passed_over.empty())
      time_course_on_sharper_rows(d, floor_inputs, passed_over, options.screen, rate, odmf);
    if (d.accepted && d.better_sensor) judge_better_sensor(d, floor_inputs, rate, odmf);
  }
  d.inseparable = inseparable_effects(model, d.screen, d.accepted ? d.accepted->effect : "");
  d.verdict = d.accepted && !d.partial             ? Verdict::kExplained
              : d.sensor_error && d.sensor_reaches ? Verdict::kAdequate
                                                   : Verdict::kStructureLeft;
  d.signature = signature_of(signature_inputs(model, segments, d, rate, odmf, options), options);
  return d;
}

}  // namespace dynid::residual
