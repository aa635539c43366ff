#include "dynid/ingest/channel_health.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <set>

#include "dynid/model/channel_catalogue.hpp"

namespace dynid::ingest {
namespace {

// 3 significant digits: a statement names a value, it does not restate the data.
std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

std::string with_unit(double x, const std::string& unit) {
  return unit == "-" || unit.empty() ? number(x) : number(x) + " " + unit;
}

std::string percent(double share) {
  return number(100.0 * share) + " %";
}

// One channel's valid samples and their grid times.
struct Series {
  std::string name, unit;
  std::vector<double> value, time;
};

Series series_of(const RecordedRun& run, Eigen::Index column) {
  const ChannelSpec& spec = run.announcement.channels[static_cast<std::size_t>(column)];
  Series s{spec.name, spec.unit, {}, {}};
  for (Eigen::Index i = 0; i < run.samples.rows(); ++i) {
    if (run.valid[static_cast<std::size_t>(i)] == 0) continue;
    s.value.push_back(run.samples(i, column));
    s.time.push_back(static_cast<double>(run.first_sample_index + static_cast<std::uint64_t>(i)) /
                     run.announcement.sample_rate_hz);
  }
  return s;
}

// The channel's quantum: the smallest non-zero step between consecutive valid samples (0 when it
// never changes). A decoded CAN signal moves by whole resolutions, a noisy one by tiny steps.
double quantum(const std::vector<double>& v) {
  double q = 0.0;
  for (std::size_t k = 1; k < v.size(); ++k) {
    const double step = std::abs(v[k] - v[k - 1]);
    if (step > 0.0 && (q == 0.0 || step < q)) q = step;
  }
  return q;
}

struct Span {
  std::size_t first = 0, last = 0;  ///< indices into the series, inclusive
  std::size_t size() const { return last - first + 1; }
};

// The longest span of consecutive samples with max - min <= q: a sliding window whose running
// minimum and maximum are kept in monotonic deques, O(n).
Span longest_held(const std::vector<double>& v, double q) {
  Span best;
  std::deque<std::size_t> lo, hi;
  std::size_t first = 0;
  for (std::size_t k = 0; k < v.size(); ++k) {
    while (!lo.empty() && v[lo.back()] >= v[k]) lo.pop_back();
    while (!hi.empty() && v[hi.back()] <= v[k]) hi.pop_back();
    lo.push_back(k);
    hi.push_back(k);
    while (v[hi.front()] - v[lo.front()] > q) {
      ++first;
      if (lo.front() < first) lo.pop_front();
      if (hi.front() < first) hi.pop_front();
    }
    if (k - first + 1 > best.size()) best = {first, k};
  }
  return best;
}

std::string span_text(const Series& s, std::size_t first, std::size_t last) {
  return "from " + number(s.time[first]) + " s to " + number(s.time[last]) + " s";
}

std::string range_text(const model::ChannelPhysics& p, const std::string& unit) {
  return "[" + number(p.lower) + ", " + number(p.upper) + "]" + (unit == "-" ? "" : " " + unit);
}

// Rules 1 and 2: samples outside the physical range, as one sentinel value or as a range fault.
std::optional<ChannelFinding> out_of_range(const Series& s, const model::ChannelPhysics& p,
                                           const HealthRules& rules) {
  std::map<double, std::size_t> count;
  std::size_t first = s.value.size(), last = 0, outside = 0;
  double extreme = 0.0;
  for (std::size_t k = 0; k < s.value.size(); ++k) {
    const double x = s.value[k];
    if (x >= p.lower && x <= p.upper) continue;
    if (outside++ == 0) first = k;
    last = k;
    ++count[x];
    if (std::abs(x) > std::abs(extreme)) extreme = x;
  }
  if (outside == 0) return std::nullopt;
  const auto top = std::max_element(
      count.begin(), count.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  const double share = static_cast<double>(outside) / static_cast<double>(s.value.size());
  const std::string where =
      span_text(s, first, last) + " (" + percent(share) + " of its valid samples)";
  if (static_cast<double>(top->second) >= rules.sentinel_share * static_cast<double>(outside))
    return ChannelFinding{HealthFinding::kSentinel,
                          s.name,
                          top->first,
                          s.time[first],
                          s.time[last],
                          share,
                          "`" + s.name + "` reads " + with_unit(top->first, s.unit) +
                              ", outside its physical range " + range_text(p, s.unit) + ", " +
                              where + ": an invalid marker, not a measurement"};
  return ChannelFinding{HealthFinding::kOutOfRange,
                        s.name,
                        extreme,
                        s.time[first],
                        s.time[last],
                        share,
                        "`" + s.name + "` is outside its physical range " + range_text(p, s.unit) +
                            " " + where + ", reaching " + with_unit(extreme, s.unit)};
}

// The median of the non-zero steps between consecutive samples: the channel's own rate.
double median_step(const std::vector<double>& v) {
  std::vector<double> steps;
  for (std::size_t k = 1; k < v.size(); ++k)
    if (const double step = std::abs(v[k] - v[k - 1]); step > 0.0) steps.push_back(step);
  if (steps.empty()) return 0.0;
  const auto middle = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), middle, steps.end());
  return *middle;
}

// Rule 2b on one side: the episodes held at `extreme` (within `tolerance`), whose signal
// kApproach samples before and after is at least `steep` and the smooth-maximum bound away from
// the extreme (header). An episode is a span of samples at the extreme and those within
// kApproach samples of it that dip off it (a noisy signal above the range touches it again and
// again); it counts with at least `min_samples` samples at the extreme. A smooth top held for L
// samples within the tolerance has a curvature of at most 8 tolerance / ((L - 1) h)^2, so j
// samples from its middle it is at most 4 tolerance (2 j / (L - 1))^2 away.
constexpr std::size_t kApproach = 3;
struct Episode {
  Span span;
  std::size_t at_extreme = 0;
};
std::vector<Episode> clipped_episodes(const std::vector<double>& v, double extreme,
                                      double tolerance, double steep, int min_samples) {
  const auto at = [&](std::size_t k) { return std::abs(v[k] - extreme) <= tolerance; };
  std::vector<Episode> out;
  for (std::size_t k = kApproach; k < v.size(); ++k) {
    if (!at(k) || at(k - 1)) continue;
    Episode e{{k, k}, 0};
    for (std::size_t i = k; i < v.size() && i <= e.span.last + kApproach; ++i)
      if (at(i)) e.span.last = i, ++e.at_extreme;
    k = e.span.last;
    // Too few samples at the extreme, or too near the series' end to judge the way out.
    if (e.span.last + kApproach >= v.size() ||
        e.at_extreme < static_cast<std::size_t>(std::max(min_samples, 2)))
      continue;
    const double j = static_cast<double>(e.span.size() - 1) / 2.0 + static_cast<double>(kApproach);
    const double smooth =
        4.0 * tolerance * std::pow(2.0 * j / static_cast<double>(e.at_extreme - 1), 2);
    const double away = std::min(std::abs(extreme - v[e.span.first - kApproach]),
                                 std::abs(extreme - v[e.span.last + kApproach]));
    if (away >= steep && away > smooth) out.push_back(e);
  }
  return out;
}

std::optional<ChannelFinding> clipped(const Series& s, const model::ChannelPhysics& p,
                                      const HealthRules& rules) {
  if (!p.inertial || s.value.size() < 3) return std::nullopt;
  const double tolerance = 1.001 * quantum(s.value);  // as rule 3's
  const double steep = median_step(s.value);
  if (!(steep > 0.0)) return std::nullopt;
  const auto [lo, hi] = std::minmax_element(s.value.begin(), s.value.end());
  std::vector<double> extremes;
  std::vector<Episode> episodes;
  for (const double extreme : {*lo, *hi}) {
    const std::vector<Episode> side =
        clipped_episodes(s.value, extreme, tolerance, steep, rules.min_clipped_samples);
    if (side.size() < static_cast<std::size_t>(rules.min_clipped_spans)) continue;
    extremes.push_back(extreme);
    episodes.insert(episodes.end(), side.begin(), side.end());
  }
  if (episodes.empty()) return std::nullopt;
  std::sort(episodes.begin(), episodes.end(),
            [](const Episode& a, const Episode& b) { return a.span.first < b.span.first; });
  std::size_t samples = 0;
  for (const Episode& e : episodes) samples += e.at_extreme;
  const double share = static_cast<double>(samples) / static_cast<double>(s.value.size());
  std::string at = number(extremes.front());
  if (extremes.size() == 2) at += " and " + number(extremes.back());
  const std::size_t first = episodes.front().span.first, last = episodes.back().span.last;
  return ChannelFinding{HealthFinding::kClipped,
                        s.name,
                        extremes.back(),
                        s.time[first],
                        s.time[last],
                        share,
                        "`" + s.name + "` clips at " + at + (s.unit == "-" ? "" : " " + s.unit) +
                            ": held there " + std::to_string(episodes.size()) + " times " +
                            span_text(s, first, last) + " (" + percent(share) +
                            " of its valid samples), each entered and left steeply: the sensor's " +
                            "range, not the car's motion"};
}

// Rule 3: the longest span held within the quantum, on a channel that holds only at rest.
std::optional<ChannelFinding> held(const Series& s, const model::ChannelPhysics& p,
                                   const HealthRules& rules) {
  if (!p.holds_only_at_rest) return std::nullopt;
  const double q = quantum(s.value);
  // A thousandth of a quantum more: decoded levels (raw * factor + offset) differ by a quantum
  // only to rounding, and nothing moves by less than a quantum.
  const Span span = longest_held(s.value, 1.001 * q);
  const double share = static_cast<double>(span.size()) / static_cast<double>(s.value.size());
  if (share < rules.min_share || s.time[span.last] - s.time[span.first] < rules.min_span_s)
    return std::nullopt;
  const auto [lo, hi] =
      std::minmax_element(s.value.begin() + static_cast<std::ptrdiff_t>(span.first),
                          s.value.begin() + static_cast<std::ptrdiff_t>(span.last) + 1);
  const double value = 0.5 * (*lo + *hi);
  // Within a quantum of rest, or of a thousandth of the range when the channel never moved (its
  // resolution is then unknown): a car standing still, or driving straight, holds it exactly.
  if (std::abs(value - p.rest) <= std::max(q, 1e-3 * (p.upper - p.lower))) return std::nullopt;
  return ChannelFinding{HealthFinding::kConstant,
                        s.name,
                        value,
                        s.time[span.first],
                        s.time[span.last],
                        share,
                        "`" + s.name + "` is constant at " + with_unit(value, s.unit) + " " +
                            span_text(s, span.first, span.last) + " (" + percent(share) +
                            " of its valid samples)"};
}

std::optional<ChannelFinding> mostly_invalid(const RecordedRun& run, const HealthRules& rules) {
  const auto rows = run.valid.size();
  if (rows == 0) return std::nullopt;
  const auto invalid = static_cast<std::size_t>(std::count(run.valid.begin(), run.valid.end(), 0));
  const double share = static_cast<double>(invalid) / static_cast<double>(rows);
  if (share < rules.max_invalid_share) return std::nullopt;
  const double rate = run.announcement.sample_rate_hz;
  const double from = static_cast<double>(run.first_sample_index) / rate;
  const double to = static_cast<double>(run.first_sample_index + rows - 1) / rate;
  return ChannelFinding{
      HealthFinding::kMostlyInvalid,
      "",
      share,
      from,
      to,
      share,
      percent(share) + " of the run's samples from " + number(from) + " s to " + number(to) +
          " s are invalid (a channel missing or stale there: the car's gap rule)"};
}

// The announced channel a model's channel name is read from: d_<name> is made from <name> by
// preprocessing unless the run measures it.
std::string source_channel(const RunAnnouncement& announcement, const std::string& name) {
  const auto announced = [&](const std::string& n) {
    return std::any_of(announcement.channels.begin(), announcement.channels.end(),
                       [&](const ChannelSpec& c) { return c.name == n; });
  };
  if (name.starts_with("d_") && !announced(name)) return name.substr(2);
  return name;
}

std::set<std::string> read_channels(const RunAnnouncement& announcement, const model::Model& model,
                                    const std::vector<std::string>& effects) {
  std::set<std::string> out;
  // Optional channels serve effects (ChannelNeed::optional): read only when an effect is on.
  for (const model::ChannelNeed& need : model.channels())
    if (!need.optional) out.insert(source_channel(announcement, need.name));
  for (const model::Effect& e : model.candidate_effects())
    if (std::find(effects.begin(), effects.end(), e.name) != effects.end())
      for (const std::string& c : e.channels) out.insert(source_channel(announcement, c));
  return out;
}

}  // namespace

RunHealth channel_health(const RecordedRun& run, const HealthRules& rules) {
  RunHealth health;
  for (Eigen::Index c = 0; c < run.samples.cols(); ++c) {
    const Series s = series_of(run, c);
    const auto physics = model::channel_physics(s.name);
    ++health.channels;
    if (s.value.empty() || !physics) continue;  // a derivative or unknown name: no range to judge
    // A sentinel is held by definition: one statement says what it is.
    auto finding = out_of_range(s, *physics, rules);
    if (!finding) finding = clipped(s, *physics, rules);
    if (!finding) finding = held(s, *physics, rules);
    if (finding) health.findings.push_back(std::move(*finding));
  }
  if (auto finding = mostly_invalid(run, rules)) health.findings.push_back(std::move(*finding));
  return health;
}

std::optional<std::string> unhealthy_reason(const RunHealth& health,
                                            const RunAnnouncement& announcement,
                                            const model::Model& model,
                                            const std::vector<std::string>& effects) {
  const std::set<std::string> reads = read_channels(announcement, model, effects);
  for (const ChannelFinding& f : health.findings)
    if (f.blocks_models() && reads.contains(f.channel)) return f.statement;
  return std::nullopt;
}

std::string not_identified(const std::string& reason) {
  return "not identified: " + reason;
}

}  // namespace dynid::ingest
