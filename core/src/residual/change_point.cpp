#include "change_point.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <Eigen/QR>

namespace dynid::residual::detail {
namespace {

// The declared rows, weighted, one matrix: [W y] per row with its time, over every group.
struct WeightedRows {
  Eigen::MatrixXd w;
  Eigen::VectorXd y;
  std::vector<double> time_s;
};

WeightedRows weighted_rows(const FoldedRows& rows, const std::vector<double>& weights) {
  const auto width = static_cast<Eigen::Index>(rows.parameters.size());
  Eigen::Index n = 0;
  for (const std::vector<double>& v : rows.collected.values) n += static_cast<Eigen::Index>(v.size()) / (width + 1);
  WeightedRows out{Eigen::MatrixXd(n, width), Eigen::VectorXd(n), {}};
  out.time_s.reserve(static_cast<std::size_t>(n));
  Eigen::Index i = 0;
  for (std::size_t g = 0; g < rows.collected.values.size(); ++g) {
    const std::vector<double>& v = rows.collected.values[g];
    const Eigen::Index m = static_cast<Eigen::Index>(v.size()) / (width + 1);
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> all(v.data(), m,
                                                                                                        width + 1);
    const double wg = g < weights.size() ? weights[g] : 1.0;
    out.w.middleRows(i, m) = wg * all.leftCols(width);
    out.y.segment(i, m) = wg * all.col(width);
    out.time_s.insert(out.time_s.end(), rows.collected.time_s[g].begin(), rows.collected.time_s[g].end());
    i += m;
  }
  return out;
}

// Row order by time, the latest first (the search runs the rows after t0 into its sums).
std::vector<Eigen::Index> latest_first(const std::vector<double>& time_s) {
  std::vector<Eigen::Index> order(time_s.size());
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
    return time_s[static_cast<std::size_t>(a)] > time_s[static_cast<std::size_t>(b)];
  });
  return order;
}

// Hansen (2000): the 95 % critical value of the change point's likelihood ratio.
constexpr double kChangePointCritical95 = 7.35;

std::string span(const char* what, double from, double to) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s %.1f-%.1f s", what, from, to);
  return buf;
}

// Gear changes within [lo, hi]: the gear (the low-passed channel, rounded) read on a grid of
// 0.5 s, so that a shift through several gears, or the filter's ramp between two, reads as one.
void gear_changes(const ingest::PreprocessedSegment& seg, double sample_rate_hz, double lo, double hi,
                  std::vector<std::string>& events) {
  const Eigen::VectorXd& gear = seg.channels["gear"];
  const auto step = std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::llround(0.5 * sample_rate_hz)));
  for (Eigen::Index k = step; k < gear.size(); k += step) {
    const double t = static_cast<double>(seg.first + k) / sample_rate_hz;
    const double before = std::round(gear(k - step)), now = std::round(gear(k));
    if (before == now || t < lo || t > hi) continue;
    char buf[96];
    std::snprintf(buf, sizeof buf, "gear %.0f -> %.0f at %.1f s", before, now, t);
    events.emplace_back(buf);
  }
}

}  // namespace

std::optional<LocatedStep> locate_step(const FoldedRows& rows, Eigen::Index column, const std::vector<double>& weights,
                                       double trim) {
  const WeightedRows r = weighted_rows(rows, weights);
  if (r.w.rows() == 0 || column < 0 || column >= r.w.cols()) return std::nullopt;
  // The declared fit: its residual e and an orthonormal basis Q of its identifiable columns.
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(r.w);
  const Eigen::Index rank = qr.rank();
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(r.w.rows(), rank);
  const Eigen::VectorXd e = r.y - q * (q.transpose() * r.y);
  const Eigen::VectorXd a = r.w.col(column);
  const auto nonzero = static_cast<double>((a.array() != 0.0).count());
  const double keep = std::max(1.0, trim * nonzero);
  const double total_aa = a.squaredNorm();
  // Sums over the rows at or after the candidate t0, run from the last row backwards.
  double s_ae = 0.0, s_aa = 0.0, after = 0.0;
  Eigen::VectorXd s_qa = Eigen::VectorXd::Zero(rank);
  struct Tried {
    double t0, previous, removed;
  };
  std::vector<Tried> tried;
  const std::vector<Eigen::Index> order = latest_first(r.time_s);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Eigen::Index i = order[k];
    s_ae += a(i) * e(i);
    s_aa += a(i) * a(i);
    s_qa += a(i) * q.row(i).transpose();
    if (a(i) != 0.0) after += 1.0;
    const double t0 = r.time_s[static_cast<std::size_t>(i)];
    if (k + 1 == order.size() || r.time_s[static_cast<std::size_t>(order[k + 1])] == t0) continue;
    if (after < keep || nonzero - after < keep) continue;
    const double independent = s_aa - s_qa.squaredNorm();
    if (!(independent > 1e-10 * total_aa)) continue;
    tried.push_back({t0, r.time_s[static_cast<std::size_t>(order[k + 1])], s_ae * s_ae / independent});
  }
  if (tried.empty()) return std::nullopt;
  const Tried& best = *std::max_element(tried.begin(), tried.end(),
                                        [](const Tried& x, const Tried& y) { return x.removed < y.removed; });
  LocatedStep out{best.t0, best.previous, best.removed, best.previous, best.t0, {}, 0.0, r.w.rows()};
  out.rss_min = std::max(e.squaredNorm() - best.removed, 0.0);
  for (const Tried& t : tried) out.tried.push_back({t.t0, t.previous, t.removed});
  return out;
}

void set_interval(LocatedStep& step, double inflation) {
  const double scale = std::isfinite(inflation) ? std::max(inflation, 1.0) : 1.0;
  const double s2 = step.rss_min / static_cast<double>(std::max<Eigen::Index>(step.rows, 1)) * scale;
  step.earliest_s = step.previous_row_s;
  step.latest_s = step.time_s;
  for (const LocatedStep::Time& t : step.tried) {
    if (!(s2 > 0.0) || (step.ss_removed - t.removed) / s2 > kChangePointCritical95) continue;
    step.earliest_s = std::min(step.earliest_s, t.previous_row_s);
    step.latest_s = std::max(step.latest_s, t.time_s);
  }
}

std::string events_near(const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz, double from_s,
                        double to_s, double margin_s) {
  const double lo = from_s - margin_s, hi = to_s + margin_s;
  std::vector<std::string> events;
  const auto time_of = [&](Eigen::Index grid) { return static_cast<double>(grid) / sample_rate_hz; };
  for (std::size_t s = 0; s < run.size(); ++s) {
    const ingest::PreprocessedSegment& seg = run[s];
    const Eigen::Index n = seg.channels.samples();
    if (s > 0) {
      const double gap_from = time_of(run[s - 1].first + run[s - 1].channels.samples());
      const double gap_to = time_of(seg.first);
      if (gap_to > lo && gap_from < hi) events.push_back(span("no valid data", gap_from, gap_to));
    }
    const bool has_speed = seg.channels.has("vx");
    Eigen::Index still_from = -1;
    for (Eigen::Index k = 0; k <= n; ++k) {
      const double t = time_of(seg.first + k);
      const bool still = k < n && has_speed && std::abs(seg.channels["vx"](k)) < 0.5;
      if (still && still_from < 0) still_from = k;
      if (!still && still_from >= 0) {
        const double a = time_of(seg.first + still_from);
        if (t > lo && a < hi) events.push_back(span("the car stood still", a, t));
        still_from = -1;
      }
    }
    if (seg.channels.has("gear")) gear_changes(seg, sample_rate_hz, lo, hi, events);
  }
  std::string out;
  for (const std::string& e : events) out += (out.empty() ? "" : "; ") + e;
  return out;
}

}  // namespace dynid::residual::detail
