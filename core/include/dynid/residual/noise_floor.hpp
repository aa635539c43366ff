#pragma once
// NoiseFloor: how large a model's residual is when the model lacks nothing, so that the residual
// loop can say "adequate: the residual is at the noise floor" before it hunts for effects. The
// argument behind each step, with what was measured: docs/decisions/noise-floor.md.
//
// 1. measure_channel_noise: each low-passed channel's noise, from the PSD of raw - low-passed
//    raw in [1.5, 3] x cut-off (Hann windows of max(32, 8 x odmf) samples, half overlapping,
//    per bin the median over the windows / ln 2), extrapolated into the band the model sees
//    (log PSD = a + b f^2) and reported as the white-noise std at the grid rate. A profile may
//    declare a channel's noise instead (source "declared").
// 2. noise_floor: each channel's share of the residual, carried through the product's own path:
//    `draws` copies of the raw run with fresh noise of that channel's sigma and a fresh time for
//    each of its steps within its sample interval (step_timing.hpp: the samples do not hold it),
//    preprocessed as the server does, rows built and fitted again; the floor is the sum of the
//    shares, with its autocorrelation (the effective number of rows of a mean square, Bartlett). A
//    channel the rows do not read (the rows come out the same with it moved) has no share and no
//    draw.
// 3. The verdict per equation group: log(residual mean square / floor mean square) against the
//    normal quantile 1 - error_rate / groups, its variance the residual's (2 / n_eff) plus the
//    floor's own (measurement bootstrap, draws). A model that lacks nothing is called
//    inadequate with probability about error_rate.
// 4. Block sums of 4, 16 and 64 decimated rows against the floor's (slow structure), reported
//    beside the verdict, not in it.
// Limits (said in the report): signal content above the cut-off counts as noise; noise that is
// not flat across the cut-off is misjudged.
#include <cstddef>
#include <cstdint>
#include <list>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::residual {

struct ChannelNoise {
  std::string channel;
  double sigma = 0.0;     ///< white-noise std at the grid rate, the channel's units
  std::string source;     ///< "measured above the cut-off" or "declared"
  /// Relative variance of sigma^2 (a bootstrap over the measurement's windows; 0 if declared).
  double level_relative_variance = 0.0;
};

/// Measured noise of every low-passed announced channel; `declared` (channel -> sigma) replaces
/// the measurement of the channels it names. Channels with too few valid samples above the
/// cut-off (no segment of 256 samples) are reported with sigma 0 and source "not measured".
std::vector<ChannelNoise> measure_channel_noise(const ingest::RecordedRun& run,
                                                const std::map<std::string, double>& declared = {});
/// The same with `segments` = preprocess_offline(run), for a caller that has them already.
std::vector<ChannelNoise> measure_channel_noise(const ingest::RecordedRun& run,
                                                const std::vector<ingest::PreprocessedSegment>& segments,
                                                const std::map<std::string, double>& declared);

/// The floor test on sums over blocks of `block_rows` consecutive decimated rows.
struct ScaleFloor {
  int block_rows = 1;
  double block_seconds = 0.0;    ///< block_rows x odmf / sample rate
  double ratio = 0.0;            ///< sum of squared block sums: residual / floor
  double effective_blocks = 0.0; ///< of that sum
  double log_ratio_std = 0.0;    ///< std of log(ratio) for a model that lacks nothing
  double upper_ratio = 0.0;      ///< the test's critical ratio
  bool at_floor = false;
};

struct GroupFloor {
  std::string group;
  std::uint64_t rows = 0;
  double residual_rms = 0.0;    ///< the declared fit's in-sample residual RMS (group units)
  double floor_rms = 0.0;       ///< what noise alone leaves
  double ratio = 0.0;           ///< residual_rms^2 / floor_rms^2
  double effective_rows = 0.0;  ///< of the variance estimate
  double floor_relative_std = 0.0;  ///< of the floor's mean square (sigmas measured, draws)
  double log_ratio_std = 0.0;   ///< std of log(ratio) for a model that lacks nothing
  double upper_ratio = 0.0;     ///< the test's critical ratio
  /// The same test on block sums (4. above), one per time scale tested.
  std::vector<ScaleFloor> scales;
  bool at_floor = false;  ///< by the rows' test (3.); the scales are evidence beside it (4.)
  /// The scale furthest above its floor (ratio / upper_ratio), nullptr when every scale is at it.
  const ScaleFloor* worst_scale() const;
};

struct NoiseFloorOptions {
  FitOptions fit;
  int draws = 4;
  std::uint64_t seed = 1;
  /// Chance of calling a model that lacks nothing inadequate: 0.025, half the loop's stated
  /// rate of false alarms (one in 20 clean runs). A clean run can raise an alarm through two
  /// tests at this level, the declared floor's and, at that floor, the better sensor's own
  /// (diagnosis.hpp): by the union bound, at most 0.05 together.
  double error_rate = 0.025;
};

struct NoiseFloor {
  std::vector<ChannelNoise> channels;
  std::vector<std::string> contributing;  ///< the channels whose noise reaches the model's rows
  std::vector<GroupFloor> groups;
  int draws = 0;
  /// Every group with rows is at its floor.
  bool adequate() const;
};

/// What the floors computed on one run share, kept across the floors of one request (the
/// declared model's, each significant candidate's, round after round of a trace): each channel's
/// noise draws, preprocessed again, and the floors already computed, by model and effects. A floor
/// computed through the cache equals one computed without it, bit for bit: every draw's noise
/// comes from its own generator, seeded by (seed, channel, draw), so it is the same whichever
/// floor asks for it first. Serves one run with one channel-noise measurement and one set of
/// NoiseFloorOptions. Memory: one preprocessed channel (and its derivative) per draw, at most
/// `draw_budget_bytes` of them; past it the draws used longest ago are dropped and, when asked
/// again, drawn again (the same draws: their generators are seeded). Not thread-safe.
class FloorCache {
 public:
  /// 256 MiB: four draws of each of 66 channels of a 10-minute run at 100 Hz, of 11 channels of a
  /// 60-minute one (a draw holds 16 bytes a sample).
  static constexpr std::size_t kDefaultDrawBudget = std::size_t{256} << 20;
  FloorCache(const ingest::RecordedRun& run,
             const std::vector<ingest::PreprocessedSegment>& segments,
             std::size_t draw_budget_bytes = kDefaultDrawBudget);
  /// `segments` with channel `column` carrying draw `draw`'s noise of `sigma`, preprocessed again.
  /// The reference holds until the next call.
  const std::vector<ingest::PreprocessedSegment>& noisy(Eigen::Index column, double sigma, int draw,
                                                        std::uint64_t seed);
  std::size_t draw_bytes() const { return draw_bytes_; }
  /// measure_channel_noise(run, segments, declared), measured once.
  const std::vector<ChannelNoise>& channel_noise(const std::map<std::string, double>& declared);
  /// The floor computed before for this model and effects, or nullptr.
  const NoiseFloor* floor(const std::string& model, const std::vector<std::string>& effects) const;
  void keep(const std::string& model, const std::vector<std::string>& effects,
            const NoiseFloor& floor);

 private:
  const ingest::RecordedRun& run_;
  const std::vector<ingest::PreprocessedSegment>& segments_;
  using DrawKey = std::tuple<Eigen::Index, double, int, std::uint64_t>;
  struct Draw {
    std::vector<ingest::PreprocessedSegment> segments;
    std::size_t bytes = 0;
    std::list<DrawKey>::iterator use;  // its place in uses_
  };
  std::size_t draw_budget_;
  std::size_t draw_bytes_ = 0;
  std::map<DrawKey, Draw> draws_;
  std::list<DrawKey> uses_;  // most recently used first
  std::map<std::pair<std::string, std::vector<std::string>>, NoiseFloor> floors_;
  std::map<std::map<std::string, double>, std::vector<ChannelNoise>> noise_;
};

/// The floor of `model` with `effects` on `run` (see above). InputError as fit_model.
NoiseFloor noise_floor(const model::Model& model, const std::vector<std::string>& effects,
                       const ingest::RecordedRun& run, const std::vector<ChannelNoise>& noise,
                       const NoiseFloorOptions& options = {});
/// The same with `segments` = preprocess_offline(run), for a caller that has them already.
NoiseFloor noise_floor(const model::Model& model, const std::vector<std::string>& effects,
                       const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                       const std::vector<ChannelNoise>& noise, const NoiseFloorOptions& options);
/// The same through `cache` (made on `run` and `segments`): a floor asked before is returned as
/// it was computed, and draws asked before are not drawn and preprocessed again.
NoiseFloor noise_floor(const model::Model& model, const std::vector<std::string>& effects,
                       const ingest::RecordedRun& run,
                       const std::vector<ingest::PreprocessedSegment>& segments,
                       const std::vector<ChannelNoise>& noise, const NoiseFloorOptions& options,
                       FloorCache& cache);

}  // namespace dynid::residual
