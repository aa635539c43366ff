#include "dynid/car/clock_offset.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "dynid/error.hpp"

namespace dynid::car {
namespace {

void check_series(const TimeSeries& s, const std::string& what, const char* which) {
  if (s.t.size() != s.v.size() || s.t.size() < 2)
    throw InputError(what + ": the " + which + " series has fewer than 2 samples");
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    if (!std::isfinite(s.t[i]) || !std::isfinite(s.v[i]))
      throw InputError(what + ": the " + which + " series holds a non-finite number at sample " + std::to_string(i));
    if (i > 0 && !(s.t[i] > s.t[i - 1]))
      throw InputError(what + ": the " + which + " series is not sorted by time at sample " + std::to_string(i));
  }
}

std::vector<double> on_grid(const TimeSeries& s, double t0, double step, std::size_t n) {
  std::vector<double> out(n);
  std::size_t j = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = t0 + static_cast<double>(i) * step;
    while (j + 2 < s.t.size() && s.t[j + 1] < t) ++j;
    const double f = std::clamp((t - s.t[j]) / (s.t[j + 1] - s.t[j]), 0.0, 1.0);
    out[i] = s.v[j] + f * (s.v[j + 1] - s.v[j]);
  }
  return out;
}

// Centred moving mean over `w` samples (shorter windows at the ends).
std::vector<double> moving_mean(const std::vector<double>& x, std::size_t w) {
  std::vector<double> prefix(x.size() + 1, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) prefix[i + 1] = prefix[i] + x[i];
  std::vector<double> out(x.size());
  const std::size_t h = w / 2;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::size_t a = i >= h ? i - h : 0;
    const std::size_t b = std::min(x.size(), i + h + 1);
    out[i] = (prefix[b] - prefix[a]) / static_cast<double>(b - a);
  }
  return out;
}

std::vector<double> prepare(std::vector<double> x, const ClockOffsetOptions& o, bool differentiate) {
  const auto samples = [&](double seconds) { return std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(seconds / o.step))); };
  x = moving_mean(x, samples(o.smooth));
  if (differentiate) {
    std::vector<double> d(x.size(), 0.0);
    for (std::size_t i = 1; i + 1 < x.size(); ++i) d[i] = (x[i + 1] - x[i - 1]) / (2.0 * o.step);
    if (x.size() > 2) d.front() = d[1], d.back() = d[d.size() - 2];
    x = std::move(d);
  }
  const std::vector<double> slow = moving_mean(x, samples(o.high_pass));
  for (std::size_t i = 0; i < x.size(); ++i) x[i] -= slow[i];
  return x;
}

// Pearson correlation of r[i] and s[i - k] over i in [a, b).
double correlation(const std::vector<double>& r, const std::vector<double>& s, long k, long a, long b) {
  a = std::max(a, k);
  b = std::min(b, static_cast<long>(s.size()) + k);
  if (b - a < 10) return 0.0;
  double sr = 0, ss = 0, srr = 0, sss = 0, srs = 0;
  for (long i = a; i < b; ++i) {
    const double x = r[static_cast<std::size_t>(i)], y = s[static_cast<std::size_t>(i - k)];
    sr += x, ss += y, srr += x * x, sss += y * y, srs += x * y;
  }
  const double n = static_cast<double>(b - a);
  const double cov = srs - sr * ss / n, vr = srr - sr * sr / n, vs = sss - ss * ss / n;
  return vr > 0 && vs > 0 ? cov / std::sqrt(vr * vs) : 0.0;
}

struct Peak {
  double lag = 0.0;  // samples
  double r = 0.0;
};

Peak best_lag(const std::vector<double>& r, const std::vector<double>& s, long max_lag, long a, long b) {
  std::vector<double> c(static_cast<std::size_t>(2 * max_lag + 1));
  for (long k = -max_lag; k <= max_lag; ++k) c[static_cast<std::size_t>(k + max_lag)] = correlation(r, s, k, a, b);
  const auto it = std::max_element(c.begin(), c.end());
  const auto i = static_cast<std::size_t>(it - c.begin());
  Peak p{static_cast<double>(static_cast<long>(i) - max_lag), *it};
  if (i > 0 && i + 1 < c.size()) {  // parabola through the peak and its neighbours
    const double den = c[i - 1] - 2.0 * c[i] + c[i + 1];
    if (den < 0) p.lag += 0.5 * (c[i - 1] - c[i + 1]) / den;
  }
  return p;
}

struct Spread {
  double centre = 0.0;
  double std = 0.0;
};

Spread robust(std::vector<double> x, double resolution) {
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  const double m = median(x);
  std::vector<double> dev;
  for (double v : x) dev.push_back(std::abs(v - m));
  const double n = static_cast<double>(x.size());
  return {m, std::max(1.4826 * median(dev) / std::sqrt(n), resolution / std::sqrt(12.0 * n))};
}

// Two-sided 1 % quantiles of Student's t (0.995) for 1..30 degrees of freedom.
double t_quantile_99(std::size_t dof) {
  static constexpr double kT[] = {63.657, 9.925, 5.841, 4.604, 4.032, 3.707, 3.499, 3.355, 3.250, 3.169,
                                  3.106,  3.055, 3.012, 2.977, 2.947, 2.921, 2.898, 2.878, 2.861, 2.845,
                                  2.831,  2.819, 2.807, 2.797, 2.787, 2.779, 2.771, 2.763, 2.756, 2.750};
  return dof == 0 ? 1e300 : dof <= 30 ? kT[dof - 1] : 2.576;
}

}  // namespace

bool ClockEstimate::drifting() const { return drift_found; }

ClockEstimate estimate_clock_offset(const TimeSeries& reference, const TimeSeries& source,
                                    const ClockOffsetOptions& o, const std::string& what) {
  check_series(reference, what, "reference");
  check_series(source, what, "source");
  const double t0 = std::max(reference.t.front(), source.t.front());
  const double t1 = std::min(reference.t.back(), source.t.back());
  if (!(t1 - t0 >= 10.0 + 2.0 * o.max_offset))
    throw InputError(what + ": the source and the bus overlap for " + std::to_string(std::max(0.0, t1 - t0)) +
                     " s, too little to estimate a clock offset within +-" + std::to_string(o.max_offset) +
                     " s (at least " + std::to_string(10.0 + 2.0 * o.max_offset) + " s): give clock = { offset = ... }");
  const auto n = static_cast<std::size_t>((t1 - t0) / o.step);
  const std::vector<double> r = prepare(on_grid(reference, t0, o.step, n), o, o.reference_derivative);
  const std::vector<double> s = prepare(on_grid(source, t0, o.step, n), o, false);
  const auto max_lag = static_cast<long>(std::lround(o.max_offset / o.step));
  const auto total = static_cast<long>(n);

  ClockEstimate e;
  const Peak whole = best_lag(r, s, max_lag, 0, total);
  e.correlation = whole.r;
  std::vector<double> all, centres;  // pieces that correlate: L and the piece's centre (s)
  std::size_t first = 0, second = 0;
  for (int p = 0; p < o.segments; ++p) {
    const long a = total * p / o.segments, b = total * (p + 1) / o.segments;
    const Peak piece = best_lag(r, s, max_lag, a, b);
    if (piece.r < o.min_correlation) continue;
    all.push_back(piece.lag * o.step);
    centres.push_back(0.5 * static_cast<double>(a + b) * o.step);
    ++(2 * p < o.segments ? first : second);
  }
  if (first < 2 || second < 2)
    throw InputError(what + ": too few parts of the run correlate (" + std::to_string(first) + " of the first half, " +
                     std::to_string(second) + " of the second, at least 2 each with correlation >= " +
                     std::to_string(o.min_correlation) + "; whole run " + std::to_string(whole.r) +
                     "): the quantity does not vary enough to estimate the clock offset; give clock = { offset = ... }");
  const Spread a = robust(all, o.step);
  e.offset = a.centre;
  e.whole_run = whole.lag * o.step;
  e.std = a.std;
  e.pieces = static_cast<int>(all.size());

  // Drift: the pieces' L against their time, a straight line by least squares; its slope tested
  // against its standard error (t quantile of n - 2 degrees of freedom at 1 %, two-sided).
  const auto m = static_cast<double>(all.size());
  double cm = 0, lm = 0;
  for (std::size_t i = 0; i < all.size(); ++i) cm += centres[i] / m, lm += all[i] / m;
  double scc = 0, scl = 0;
  for (std::size_t i = 0; i < all.size(); ++i) scc += (centres[i] - cm) * (centres[i] - cm), scl += (centres[i] - cm) * (all[i] - lm);
  const double slope = scl / scc;
  double sse = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const double res = all[i] - lm - slope * (centres[i] - cm);
    sse += res * res;
  }
  const double resolution = o.step / std::sqrt(12.0);  // a piece's L is no finer than its grid
  const double piece_sd = std::max(std::sqrt(sse / (m - 2.0)), resolution);
  const double slope_se = piece_sd / std::sqrt(scc);
  const double span = centres.back() - centres.front();
  e.start = lm + slope * (centres.front() - cm);
  e.end = lm + slope * (centres.back() - cm);
  e.start_std = e.end_std = piece_sd * std::sqrt(1.0 / m + (span / 2) * (span / 2) / scc);
  e.drift = slope;
  e.drift_std = slope_se;
  e.drift_found = std::abs(slope) > t_quantile_99(all.size() - 2) * slope_se && std::abs(slope * span) > 2.0 * o.step;
  return e;
}

}  // namespace dynid::car
