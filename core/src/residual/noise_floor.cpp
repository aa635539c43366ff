#include "dynid/residual/noise_floor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <set>

#include <Eigen/QR>
#include <boost/math/distributions/normal.hpp>

#include "dynid/cancellation.hpp"
#include "dynid/error.hpp"
#include "dynid/residual/step_timing.hpp"
#include "folded_rows.hpp"

namespace dynid::residual {
namespace {

// The noise is measured on short windows of kWindowRowsPerOdmf x odmf samples (0.64 s at 100 Hz,
// odmf 8): the median over windows ignores a transient only when fewer than half the windows hold
// one, and a launch or acceleration run shifts gear every few seconds. With 256-sample windows
// (2.6 s) most windows of such runs held a shift's torque step, and the measured noise read
// 1.3-2.2 times the true wheel torque noise and 1.4 times the true ax noise on bench/trace's
// second car (vx 15 % low); with 64 it reads within 0-25 %. Scaling with odmf keeps the band's
// bin count whatever the decimation (the band is [1.5, 3] x a cut-off of 0.4 fs / odmf: about 5
// bins of fs / window), enough for its extrapolation (in_band_level).
constexpr Eigen::Index kWindowRowsPerOdmf = 8;
constexpr Eigen::Index kMinWindow = 32;
constexpr double kBandLow = 1.5;   // x cut-off
constexpr double kBandHigh = 3.0;  // x cut-off
constexpr int kMaxLags = 40;       // decimated rows, for the effective number of rows
constexpr std::array<int, 3> kBlockRows = {4, 16, 64};  // the longer time scales (header, 4.)
constexpr double kMinBlocks = 8.0;  // fewer blocks: log of a chi-square too far from normal

bool filtered(const ingest::RunAnnouncement& a, const std::string& channel) {
  const auto& pass = a.preprocessing.unfiltered;
  return std::find(pass.begin(), pass.end(), channel) == pass.end();
}

Eigen::VectorXd hann_window(Eigen::Index n) {
  Eigen::VectorXd window(n);
  for (Eigen::Index i = 0; i < n; ++i)
    window(i) = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                     static_cast<double>(n));
  return window;
}

// One-sided PSD of x at the bins of [low, high] Hz: Hann windows of `window` samples, half
// overlapping; the DFT is evaluated at the band's bins only. Keeps every window's periodogram
// value per bin so that segments pool and the median can be taken: the median over windows
// (Welch's mean made robust, divided by ln 2, the median of an exponential variable over its
// mean) ignores the few windows that hold a transient (a gear shift rings the driveline above
// the cut-off for a second), which are signal, not noise.
struct BandPsd {
  Eigen::Index window = kMinWindow;
  std::vector<double> frequency;
  std::vector<double> gain;  // [bin]: the share of white noise the bin reads (bin_gain)
  std::vector<std::vector<double>> values;  // [bin][window]
  long windows = 0;
  double level(std::size_t bin) const {
    std::vector<double> v = values[bin];
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2] / std::numbers::ln2 / gain[bin];
  }
};

// The share of a white noise's PSD that the bin at `bin_hz` reads: the measurement looks at raw
// minus low-passed raw, whose power response is (1 - |H|^2)^2 (the zero-phase filter's response
// is |H|^2, butterworth.hpp), seen through the Hann window's leakage (its power kernel about the
// bin, over the whole periodic band). Why: the window's main lobe reaches into the filter's
// transition below the band, so the lowest bin read 4 % of white noise low at 1.5 times the
// cut-off (order 5), and the extrapolation into the band carried that as a floor 4 % low. The
// bin is divided by it: exact for white noise, and for any noise smooth across the kernel.
double bin_gain(double bin_hz, double rate, Eigen::Index window, int order, double cutoff) {
  constexpr int kPoints = 2048;  // over [0, rate): far finer than the kernel's lobes
  const double pi = std::numbers::pi;
  const double tan_cutoff = std::tan(pi * cutoff / rate);
  const Eigen::VectorXd hann = hann_window(window);
  double weighted = 0.0;
  double total = 0.0;
  for (int k = 0; k < kPoints; ++k) {
    const double f = rate * (static_cast<double>(k) + 0.5) / kPoints;
    const double folded = std::min(f, rate - f);
    const double h2 =
        1.0 / (1.0 + std::pow(std::tan(pi * folded / rate) / tan_cutoff, 2.0 * order));
    double re = 0.0;
    double im = 0.0;
    const double w = 2.0 * pi * (f - bin_hz) / rate;
    for (Eigen::Index i = 0; i < window; ++i) {
      re += hann(i) * std::cos(w * static_cast<double>(i));
      im -= hann(i) * std::sin(w * static_cast<double>(i));
    }
    const double kernel = re * re + im * im;
    weighted += kernel * (1.0 - h2) * (1.0 - h2);
    total += kernel;
  }
  return weighted / total;
}

void add_band_psd(const Eigen::VectorXd& x, double rate, BandPsd& psd) {
  const Eigen::Index n = psd.window;
  const Eigen::VectorXd window = hann_window(n);
  const double window_power = window.squaredNorm();
  for (Eigen::Index start = 0; start + n <= x.size(); start += n / 2) {
    Eigen::VectorXd piece = x.segment(start, n);
    piece.array() -= piece.mean();
    piece.array() *= window.array();
    for (std::size_t b = 0; b < psd.frequency.size(); ++b) {
      double re = 0.0;
      double im = 0.0;
      const double w = 2.0 * std::numbers::pi * psd.frequency[b] / rate;
      for (Eigen::Index i = 0; i < n; ++i) {
        re += piece(i) * std::cos(w * static_cast<double>(i));
        im -= piece(i) * std::sin(w * static_cast<double>(i));
      }
      psd.values[b].push_back(2.0 * (re * re + im * im) / (rate * window_power));
    }
    ++psd.windows;
  }
}

BandPsd band_bins(double rate, int odmf, double low, double high, int order, double cutoff) {
  BandPsd psd;
  psd.window = std::max(kMinWindow, kWindowRowsPerOdmf * odmf);
  const double resolution = rate / static_cast<double>(psd.window);
  for (auto k = static_cast<long>(std::ceil(low / resolution));
       static_cast<double>(k) * resolution <= high; ++k) {
    psd.frequency.push_back(static_cast<double>(k) * resolution);
    psd.gain.push_back(bin_gain(psd.frequency.back(), rate, psd.window, order, cutoff));
  }
  psd.values.resize(psd.frequency.size());
  return psd;
}

// The mean noise PSD inside the band [0, cutoff], extrapolated from the bins above it. A noise
// spectrum is even in f and smooth near 0, so its logarithm is a + b f^2 there (least squares
// over the bins' log levels); a channel interpolated onto the grid from a slower message falls
// off as sinc^4, which is that shape to second order. The in-band mean is the mean of
// exp(a + b f^2) over [0, fc]. The slope is kept even where it is not significant: nearly every
// channel is interpolated onto the grid between frames, which tilts even white sensor noise (a
// frame time 30 % of a step from the grid mixes two frames: 12 % more noise power below the
// cut-off than between 1.5 and 3 times it, measured on coast-downs as a floor 8-17 % low when the
// slope was dropped); the extrapolation's extra variance is counted (level_relative_variance).
double in_band_level(const BandPsd& psd, double cutoff) {
  const auto bins = static_cast<Eigen::Index>(psd.frequency.size());
  Eigen::MatrixXd a(bins, 2);
  Eigen::VectorXd level(bins);
  for (Eigen::Index b = 0; b < bins; ++b) {
    a(b, 0) = 1.0;
    a(b, 1) = psd.frequency[static_cast<std::size_t>(b)] * psd.frequency[static_cast<std::size_t>(b)];
    level(b) = psd.level(static_cast<std::size_t>(b));
  }
  const double mean = level.mean();
  if (bins < 4 || (level.array() <= 0.0).any()) return mean;
  const Eigen::VectorXd y = level.array().log().matrix();
  const Eigen::Vector2d c = a.colPivHouseholderQr().solve(y);
  constexpr int kSteps = 64;  // midpoint rule over [0, fc]
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double f = cutoff * (static_cast<double>(i) + 0.5) / kSteps;
    sum += std::exp(c(0) + c(1) * f * f);
  }
  const double extrapolated = sum / kSteps;
  return std::isfinite(extrapolated) && extrapolated > 0.0 ? extrapolated : mean;
}

// The relative variance of in_band_level, as the variance of its logarithm (the floor test is on
// log ratios): a bootstrap over the windows (the same windows for every bin, so that the bins'
// correlation is kept), kBootstrap resamples, a fixed seed; the scale of the replicates' logs
// from their variance. Why the logarithm: on short runs a few resamples make the quadratic
// extrapolation blow up by orders of magnitude, and the plain relative variance of the levels
// then reached 270-1630 (launch runs of bench/trace, the clamp load), which made the floor test
// powerless; the logarithm is the scale the test works on, and for a well-behaved channel both
// agree (the log's variance is the relative variance to first order).
double level_relative_variance(const BandPsd& psd, double cutoff, double level) {
  constexpr int kBootstrap = 40;
  if (!(level > 0.0)) return 0.0;
  std::mt19937_64 rng(0x6e6f697365ULL);
  std::uniform_int_distribution<std::size_t> pick(0, psd.values.front().size() - 1);
  std::vector<double> logs;
  for (int b = 0; b < kBootstrap; ++b) {
    BandPsd resampled{psd.window, psd.frequency, psd.gain,
                      std::vector<std::vector<double>>(psd.values.size()), psd.windows};
    for (std::size_t w = 0; w < psd.values.front().size(); ++w) {
      const std::size_t from = pick(rng);
      for (std::size_t bin = 0; bin < psd.values.size(); ++bin) resampled.values[bin].push_back(psd.values[bin][from]);
    }
    const double v = in_band_level(resampled, cutoff);
    if (std::isfinite(v) && v > 0.0) logs.push_back(std::log(v));
  }
  if (logs.size() < 2) return 0.0;
  double mean = 0.0;
  for (double l : logs) mean += l;
  mean /= static_cast<double>(logs.size());
  double ss = 0.0;
  for (double l : logs) ss += (l - mean) * (l - mean);
  return ss / static_cast<double>(logs.size() - 1);
}

// What one draw's noise did to the residual, at the rows both runs keep.
std::vector<std::pair<Eigen::Index, double>> difference(const std::vector<std::pair<Eigen::Index, double>>& noisy,
                                                        const std::vector<std::pair<Eigen::Index, double>>& base) {
  std::vector<std::pair<Eigen::Index, double>> out;
  std::size_t j = 0;
  for (const auto& [grid, r] : noisy) {
    while (j < base.size() && base[j].first < grid) ++j;
    if (j < base.size() && base[j].first == grid) out.emplace_back(grid, r - base[j].second);
  }
  return out;
}

// Sums of the noise residual's squares and lagged products, over draws.
struct LagSums {
  double square = 0.0;
  std::vector<double> lagged = std::vector<double>(kMaxLags + 1, 0.0);
  long rows = 0;
  void add(const std::vector<std::pair<Eigen::Index, double>>& d, int odmf) {
    // The lag of each grid distance up to the last one counted, looked up rather than divided:
    // this loop runs kMaxLags times per row of every draw.
    const Eigen::Index reach = static_cast<Eigen::Index>(kMaxLags + 1) * odmf;
    std::vector<std::size_t> lag_of(static_cast<std::size_t>(reach));
    for (Eigen::Index gap = 0; gap < reach; ++gap)
      lag_of[static_cast<std::size_t>(gap)] = static_cast<std::size_t>(gap / odmf);
    for (std::size_t i = 0; i < d.size(); ++i) {
      square += d[i].second * d[i].second;
      ++rows;
      for (std::size_t j = i; j-- > 0;) {
        const Eigen::Index gap = d[i].first - d[j].first;
        if (gap >= reach) break;
        lagged[lag_of[static_cast<std::size_t>(gap)]] += d[i].second * d[j].second;
      }
    }
  }
  // n / (1 + 2 sum rho_k^2), the sum stopped at the first lag within the noise of rho.
  double effective_rows(double n) const {
    if (square <= 0.0) return n;
    const double noise = 2.0 / std::sqrt(static_cast<double>(rows));
    double sum = 0.0;
    for (int k = 1; k <= kMaxLags; ++k) {
      const double rho = lagged[static_cast<std::size_t>(k)] / square;
      if (std::abs(rho) < noise) break;
      sum += rho * rho;
    }
    return n / (1.0 + 2.0 * sum);
  }
};

// The sums of `r` over blocks of `block_grid` grid samples (grid / block_grid), as a series on
// the block index: blocks span gaps and segment edges alike in the residual and in the draws.
std::vector<std::pair<Eigen::Index, double>> block_sums(const std::vector<std::pair<Eigen::Index, double>>& r,
                                                        Eigen::Index block_grid) {
  std::vector<std::pair<Eigen::Index, double>> out;
  for (const auto& [grid, value] : r) {
    const Eigen::Index block = grid / block_grid;
    if (out.empty() || out.back().first != block) out.emplace_back(block, 0.0);
    out.back().second += value;
  }
  return out;
}

// One time scale's sums over the draws of every contributing channel, per group.
struct ScaleSums {
  std::vector<std::vector<LagSums>> share;  // [channel][group]
};

// Channel `column` of the run with draw `draw`'s noise of `sigma`. Each draw has its own
// generator, seeded by (seed, channel, draw): a draw is the same whichever floor asks for it and
// whatever channels that floor's model reads, so that draws can be shared (FloorCache) and a
// floor does not depend on how the question was asked.
Eigen::VectorXd with_noise(const ingest::RecordedRun& run, Eigen::Index column, double sigma,
                           int draw, std::uint64_t seed) {
  const std::string& channel = run.announcement.channels.at(static_cast<std::size_t>(column)).name;
  std::vector<std::uint32_t> key{static_cast<std::uint32_t>(seed),
                                 static_cast<std::uint32_t>(seed >> 32),
                                 static_cast<std::uint32_t>(draw)};
  key.insert(key.end(), channel.begin(), channel.end());
  std::seed_seq sequence(key.begin(), key.end());
  std::mt19937_64 rng(sequence);
  Eigen::VectorXd noisy = run.samples.col(column);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (Eigen::Index i = 0; i < noisy.size(); ++i) noisy(i) += sigma * normal(rng);
  // The timing of the channel's steps within their sample intervals, which the samples do not
  // hold (step_timing.hpp), drawn after the noise: a run without steps draws what it drew before.
  add_step_timing(find_steps(run.samples.col(column), run.valid, sigma), rng, noisy);
  return noisy;
}

Eigen::Index column_of(const ingest::RunAnnouncement& a, const std::string& channel) {
  for (std::size_t j = 0; j < a.channels.size(); ++j)
    if (a.channels[j].name == channel) return static_cast<Eigen::Index>(j);
  return -1;
}

// The floor's share sums of one group pooled over the channels (independent sensors: the mean
// squares and lagged products add), with the variance of the pooled mean square that the
// channels' measured sigmas carry.
struct PooledFloor {
  LagSums total;
  double variance = 0.0;
};

PooledFloor pool(const std::vector<std::vector<LagSums>>& shares, std::size_t g,
                 const std::vector<double>& share_relative_variance) {
  PooledFloor out;
  for (std::size_t c = 0; c < shares.size(); ++c) {
    const LagSums& share = shares[c][g];
    if (share.rows == 0) continue;
    const double ms = share.square / static_cast<double>(share.rows);
    out.variance += ms * ms * share_relative_variance[c];
    out.total.square += ms;
    for (std::size_t k = 0; k < out.total.lagged.size(); ++k)
      out.total.lagged[k] += share.lagged[k] / static_cast<double>(share.rows);
    out.total.rows = std::max(out.total.rows, share.rows);
  }
  return out;
}

// log(residual mean square / floor mean square) under "the model lacks nothing": the residual's
// mean square is chi2(n_eff) / n_eff (variance 2 / n_eff), the floor's has the relative variance
// of its sigmas and of its draws (2 / (draws n_eff)). `n` terms in the residual's mean square.
struct LogRatio {
  double ratio = 0.0;
  double effective = 0.0;
  double floor_relative_std = 0.0;
  double std = 0.0;
};

LogRatio log_ratio(const PooledFloor& floor, double residual_mean_square, double n, int draws) {
  LogRatio out;
  const double ms = floor.total.square;
  out.ratio = residual_mean_square / ms;
  out.effective = std::max(1.0, floor.total.effective_rows(n));
  out.floor_relative_std = std::sqrt(floor.variance / (ms * ms) + 2.0 / (draws * out.effective));
  out.std = std::sqrt(2.0 / out.effective + out.floor_relative_std * out.floor_relative_std);
  return out;
}

double mean_square(const std::vector<std::pair<Eigen::Index, double>>& r) {
  double ss = 0.0;
  for (const auto& [grid, value] : r) ss += value * value;
  return r.empty() ? 0.0 : ss / static_cast<double>(r.size());
}

// One group's floor test at every time scale (header, 3. and 4.); `tested`: the groups with rows.
GroupFloor group_floor(const std::string& group, const std::vector<std::pair<Eigen::Index, double>>& residual,
                       const std::vector<std::vector<LagSums>>& shares, const std::vector<ScaleSums>& scale_shares,
                       std::size_t g, const std::vector<double>& share_relative_variance, int odmf,
                       double rate, const NoiseFloorOptions& options, double tested) {
  GroupFloor f;
  f.group = group;
  f.rows = residual.size();
  const auto n = static_cast<double>(f.rows);
  const double ms = mean_square(residual);
  f.residual_rms = std::sqrt(ms);
  const PooledFloor floor = pool(shares, g, share_relative_variance);
  if (f.rows == 0 || floor.total.square <= 0.0) {  // no noise reaches the rows: only an exact fit is at the floor
    f.at_floor = f.residual_rms <= std::numeric_limits<double>::epsilon() * (1.0 + std::sqrt(ms * n));
    return f;
  }
  f.floor_rms = std::sqrt(floor.total.square);
  const LogRatio rows = log_ratio(floor, ms, n, options.draws);
  f.ratio = rows.ratio;
  f.effective_rows = rows.effective;
  f.floor_relative_std = rows.floor_relative_std;
  f.log_ratio_std = rows.std;
  std::vector<ScaleFloor> scales;
  for (std::size_t s = 0; s < kBlockRows.size(); ++s) {
    const auto blocks = block_sums(residual, static_cast<Eigen::Index>(kBlockRows[s]) * odmf);
    const auto count = static_cast<double>(blocks.size());
    const PooledFloor block_floor = pool(scale_shares[s].share, g, share_relative_variance);
    if (count < kMinBlocks || block_floor.total.square <= 0.0) continue;
    const LogRatio test = log_ratio(block_floor, mean_square(blocks), count, options.draws);
    ScaleFloor scale;
    scale.block_rows = kBlockRows[s];
    scale.block_seconds = kBlockRows[s] * odmf / rate;
    scale.ratio = test.ratio;
    scale.effective_blocks = test.effective;
    scale.log_ratio_std = test.std;
    scales.push_back(scale);
  }
  // The rows' test decides (at error_rate over the groups, as before the scales); the scales
  // are evidence beside it, each family of them at the same level (header, 4.).
  const double z = boost::math::quantile(boost::math::normal(), 1.0 - options.error_rate / tested);
  f.upper_ratio = std::exp(z * f.log_ratio_std);
  f.at_floor = f.ratio <= f.upper_ratio;
  const double z_scales = boost::math::quantile(
      boost::math::normal(), 1.0 - options.error_rate / (tested * static_cast<double>(std::max<std::size_t>(scales.size(), 1))));
  for (ScaleFloor& scale : scales) {
    scale.upper_ratio = std::exp(z_scales * scale.log_ratio_std);
    scale.at_floor = scale.ratio <= scale.upper_ratio;
  }
  f.scales = std::move(scales);
  return f;
}

}  // namespace

std::vector<ChannelNoise> measure_channel_noise(const ingest::RecordedRun& run,
                                                const std::map<std::string, double>& declared) {
  return measure_channel_noise(run, ingest::preprocess_offline(run), declared);
}

std::vector<ChannelNoise> measure_channel_noise(const ingest::RecordedRun& run,
                                                const std::vector<ingest::PreprocessedSegment>& segments,
                                                const std::map<std::string, double>& declared) {
  const ingest::RunAnnouncement& a = run.announcement;
  const double rate = a.sample_rate_hz;
  const double cutoff = a.preprocessing.cutoff(rate);
  const double low = kBandLow * cutoff;
  const double high = std::min(kBandHigh * cutoff, 0.9 * rate / 2.0);
  const BandPsd bins =
      band_bins(rate, a.preprocessing.odmf, low, high, a.preprocessing.butterworth_order, cutoff);
  std::vector<ChannelNoise> out;
  for (std::size_t j = 0; j < a.channels.size(); ++j) {
    const std::string& name = a.channels[j].name;
    if (!filtered(a, name)) continue;
    if (const auto d = declared.find(name); d != declared.end()) {
      out.push_back({name, d->second, "declared"});
      continue;
    }
    BandPsd psd = bins;
    for (const ingest::PreprocessedSegment& s : segments) {
      const Eigen::Index length = s.channels.samples();
      const Eigen::Index at = s.first - static_cast<Eigen::Index>(run.first_sample_index);
      const Eigen::VectorXd raw = run.samples.block(at, static_cast<Eigen::Index>(j), length, 1);
      add_band_psd(raw - s.channels[name], rate, psd);
    }
    if (psd.windows == 0 || psd.frequency.empty()) {
      out.push_back({name, 0.0, "not measured"});
      continue;
    }
    const double level = in_band_level(psd, cutoff);
    out.push_back({name, std::sqrt(level * rate / 2.0), "measured above the cut-off",
                   level_relative_variance(psd, cutoff, level)});
  }
  return out;
}

const ScaleFloor* GroupFloor::worst_scale() const {
  const ScaleFloor* worst = nullptr;
  for (const ScaleFloor& s : scales)
    if (!s.at_floor && (worst == nullptr || s.ratio / s.upper_ratio > worst->ratio / worst->upper_ratio)) worst = &s;
  return worst;
}

bool NoiseFloor::adequate() const {
  return std::all_of(groups.begin(), groups.end(), [](const GroupFloor& g) { return g.rows == 0 || g.at_floor; });
}

NoiseFloor noise_floor(const model::Model& model, const std::vector<std::string>& effects,
                       const ingest::RecordedRun& run, const std::vector<ChannelNoise>& noise,
                       const NoiseFloorOptions& options) {
  return noise_floor(model, effects, run, ingest::preprocess_offline(run), noise, options);
}

FloorCache::FloorCache(const ingest::RecordedRun& run,
                       const std::vector<ingest::PreprocessedSegment>& segments,
                       std::size_t draw_budget_bytes)
    : run_(run), segments_(segments), draw_budget_(draw_budget_bytes) {}

const std::vector<ingest::PreprocessedSegment>& FloorCache::noisy(Eigen::Index column, double sigma,
                                                                  int draw, std::uint64_t seed) {
  const DrawKey key{column, sigma, draw, seed};
  if (const auto it = draws_.find(key); it != draws_.end()) {
    uses_.splice(uses_.begin(), uses_, it->second.use);
    return it->second.segments;
  }
  std::vector<ingest::PreprocessedSegment> segments = ingest::preprocess_channel_again(
      run_, segments_, column, with_noise(run_, column, sigma, draw, seed));
  // What the draw holds of its own: the channel and its derivative, every other channel shared.
  std::size_t bytes = 0;
  for (const ingest::PreprocessedSegment& s : segments)
    bytes += 2 * sizeof(double) * static_cast<std::size_t>(s.channels.samples());
  while (!uses_.empty() && draw_bytes_ + bytes > draw_budget_) {
    const auto oldest = draws_.find(uses_.back());
    draw_bytes_ -= oldest->second.bytes;
    draws_.erase(oldest);
    uses_.pop_back();
  }
  uses_.push_front(key);
  draw_bytes_ += bytes;
  return draws_.emplace(key, Draw{std::move(segments), bytes, uses_.begin()})
      .first->second.segments;
}

const std::vector<ChannelNoise>& FloorCache::channel_noise(
    const std::map<std::string, double>& declared) {
  auto it = noise_.find(declared);
  if (it == noise_.end())
    it = noise_.emplace(declared, measure_channel_noise(run_, segments_, declared)).first;
  return it->second;
}

const NoiseFloor* FloorCache::floor(const std::string& model,
                                    const std::vector<std::string>& effects) const {
  const auto it = floors_.find({model, effects});
  return it == floors_.end() ? nullptr : &it->second;
}

void FloorCache::keep(const std::string& model, const std::vector<std::string>& effects,
                      const NoiseFloor& floor) {
  floors_.insert_or_assign({model, effects}, floor);
}

NoiseFloor noise_floor(const model::Model& model, const std::vector<std::string>& effects,
                       const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                       const std::vector<ChannelNoise>& noise, const NoiseFloorOptions& options) {
  FloorCache cache(run, segments);
  return noise_floor(model, effects, run, segments, noise, options, cache);
}

NoiseFloor noise_floor(const model::Model& model, const std::vector<std::string>& effects,
                       const ingest::RecordedRun& run,
                       const std::vector<ingest::PreprocessedSegment>& segments,
                       const std::vector<ChannelNoise>& noise, const NoiseFloorOptions& options,
                       FloorCache& cache) {
  if (const NoiseFloor* known = cache.floor(model.name(), effects)) return *known;
  if (options.draws < 1) throw InputError("noise floor: draws " + std::to_string(options.draws) + " < 1");
  if (segments.empty()) throw InputError("noise floor of " + model.name() + ": the run has no valid segment");
  const double rate = run.announcement.sample_rate_hz;
  const int odmf = run.announcement.preprocessing.odmf;
  FitOptions fit_options = options.fit;
  fit_options.series = false;
  // Double precision: a share is the difference of two fits of one model, noise of the sensors'
  // size apart, far above double rounding; every fit of the floor (the base too, so that a draw
  // that changes no row leaves a share of exactly 0) folds with LAPACK's blocked kernel.
  fit_options.precision = ls::Precision::kDouble;
  // The channels the rows look up: any other cannot be read (ChannelLookupProbe), so only these
  // are put to reads_channel's test, which builds the rows again for each.
  std::set<std::string> looked_up;
  const detail::FoldedRows base = [&] {
    model::ChannelLookupProbe lookups;
    detail::FoldedRows rows =
        detail::fold_rows(model, effects, segments, rate, odmf, fit_options, true);
    looked_up = lookups.looked_up();
    return rows;
  }();
  const Eigen::VectorXd x = detail::solution(base);
  const detail::GridResiduals r0 = detail::residuals_at(base, x);
  const detail::RowSelection rows = detail::kept_rows(model, effects, segments, rate, odmf);
  // One channel at a time: the floor is the sum of the channels' shares, and each share's
  // uncertainty (its sigma's, measured) is carried on its own. A channel the rows do not read
  // (most of a car's) gets no draw: its noise would leave the residual exactly unchanged. A
  // channel the rows read whose noise leaves the residual unchanged all the same gets one draw.
  std::vector<std::vector<LagSums>> shares;  // [channel][group]
  std::vector<ScaleSums> scale_shares(kBlockRows.size());
  std::vector<double> share_relative_variance;
  std::vector<std::string> contributing;
  for (const ChannelNoise& c : noise) {
    const Eigen::Index column = column_of(run.announcement, c.channel);
    if (column < 0 || !(c.sigma > 0.0)) continue;
    const std::string derivative =
        column_of(run.announcement, "d_" + c.channel) < 0 ? "d_" + c.channel : "";
    const bool seen = looked_up.count(c.channel) > 0 || looked_up.count("d_" + c.channel) > 0;
    if (!seen || !detail::reads_channel(base, model, effects, segments, rate, odmf, fit_options,
                                        c.channel, derivative, c.sigma))
      continue;
    std::vector<LagSums> sums(r0.size());
    std::vector<std::vector<LagSums>> blocks(kBlockRows.size(), std::vector<LagSums>(r0.size()));
    for (int d = 0; d < options.draws; ++d) {
      cancellation_point();
      const auto& noisy = cache.noisy(column, c.sigma, d, options.seed);
      // Refitted: the draw's own least squares, so that the attenuation its noise causes in the
      // parameters of a noisy regressor (errors in variables, slow like the signals) is in the
      // share, as the run's own noise put it into the run's residual (header, 2.).
      const detail::FoldedRows folded = detail::fold_rows(model, effects, noisy, rate, odmf, fit_options, true, &rows);
      const detail::GridResiduals r1 = detail::residuals_at(folded, detail::solution(folded));
      for (std::size_t g = 0; g < sums.size(); ++g) {
        const auto share = difference(r1[g], r0[g]);
        sums[g].add(share, odmf);
        for (std::size_t s = 0; s < kBlockRows.size(); ++s)
          blocks[s][g].add(block_sums(share, static_cast<Eigen::Index>(kBlockRows[s]) * odmf), 1);
      }
      if (d == 0 && std::all_of(sums.begin(), sums.end(), [](const LagSums& l) { return l.square == 0.0; })) break;
    }
    if (std::all_of(sums.begin(), sums.end(), [](const LagSums& l) { return l.square == 0.0; })) continue;
    shares.push_back(std::move(sums));
    for (std::size_t s = 0; s < kBlockRows.size(); ++s) scale_shares[s].share.push_back(std::move(blocks[s]));
    contributing.push_back(c.channel);
    share_relative_variance.push_back(c.level_relative_variance);
  }
  NoiseFloor out;
  out.channels = noise;
  out.contributing = contributing;
  out.draws = options.draws;
  const auto tested = static_cast<double>(std::count_if(r0.begin(), r0.end(), [](const auto& r) { return !r.empty(); }));
  for (std::size_t g = 0; g < r0.size(); ++g)
    out.groups.push_back(group_floor(base.groups[g], r0[g], shares, scale_shares, g, share_relative_variance,
                                     odmf, rate, options, tested));
  cache.keep(model.name(), effects, out);
  return out;
}

}  // namespace dynid::residual
