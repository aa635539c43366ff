#pragma once
// Channel health: what a stored run's raw samples (ingest::RecordedRun, before preprocessing)
// say about each channel's sensor, so that no model is judged on a channel that did not measure.
// A stuck accelerometer, or a torque that is the DBC's invalid marker for the whole run, gives
// estimates and verdicts that read as results ("adequate: the residual is at the noise floor")
// while the data hold no information; the health findings say so in one line instead.
//
// Rules, per announced channel, over its valid samples (RecordedRun::valid), in this order:
// 1. Sentinel: the samples outside the channel's physical range (model::channel_physics) are, for
//    at least `sentinel_share` of them, one exact value: an invalid marker (a DBC's all-ones
//    raw value, an ECU's "not available"), not a measurement. Otherwise
// 2. Out of range: any valid sample outside the physical range. The ranges are impossibilities
//    on a car, so one such sample already says the decoding or the sensor is wrong.
// 2b. Clipped: on an inertial sensor (model::ChannelPhysics::inertial), the channel's largest
//    or smallest value is held, within its quantum, on at least `min_clipped_spans` separate
//    spans of at least `min_clipped_samples` samples, and 3 samples before and after each span
//    the signal is at least the channel's median step away from that value and further than a
//    smooth maximum can be. Why that says "clipped": a smooth top held within a quantum q for L
//    samples has a curvature of at most 8 q / ((L - 1) h)^2, so j samples from its middle it is
//    at most 4 q (2 j / (L - 1))^2 below; a peak cut off by the sensor's range is entered and
//    left at the signal's own rate. Several spans: a single one can be a steady state. Channels
//    with an end stop or a limiter behind them (a steer at full lock, an engine at its rev limit, a
//    closed clutch's load) hold flat tops of their own and are not judged.
// 3. Constant (stuck): the longest span of consecutive valid samples whose values stay within
//    the channel's quantum (the smallest non-zero step between consecutive valid samples seen
//    anywhere in the run, 0 for a channel that never changes: a sensor cannot resolve less, so
//    a span within it carries no change at all) lasts at least `min_span_s` seconds and holds
//    at least `min_share` of the channel's valid samples, on a channel that a car holds only at
//    its rest value (model::ChannelPhysics::holds_only_at_rest: `ax`, `az`, the roll and pitch
//    rates), at a value more than a quantum (or a thousandth of its range) from that rest. Other
//    channels hold exactly in any steady state on a quantised noise-free record (a cruise's
//    speed, steady cornering's yaw rate and steer, a static load, idle), so a held span of
//    theirs is not a fault; their stuck sensors are not found by this rule.
// 4. Invalid share: when at least `max_invalid_share` of the run's samples are invalid, one
//    run-wide finding (validity is per grid row: the car knows which signal was missing, the run
//    does not). It is reported, but blocks no model: the valid rows still identify.
//
// Each finding carries a one-line statement naming the channel, the value with its unit, the
// time span (s from the run's grid origin) and the share, e.g. "`ax` is constant at -0.57 m/s^2
// from 3.1 s to 36 s (92 % of its valid samples)".
//
// unhealthy_reason() is the one decision every reply takes: "may this model be judged on this
// run?". It returns the first blocking finding of any channel the model reads (its required
// channels and those of its enabled effects: an optional channel serves an effect; d_<name>
// stands for <name> when the run does not measure the derivative itself), nullopt when none.
#include <optional>
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"

namespace dynid::ingest {

struct HealthRules {
  double min_span_s = 5.0;         ///< rule 3: a held span at least this long, and
  double min_share = 0.5;          ///< rule 3: holding at least this share of the valid samples
  double sentinel_share = 0.5;     ///< rule 1: share of the out-of-range samples at one value
  double max_invalid_share = 0.5;  ///< rule 4
  int min_clipped_spans = 3;       ///< rule 2b
  int min_clipped_samples = 3;     ///< rule 2b: of each span
};

enum class HealthFinding { kSentinel, kOutOfRange, kClipped, kConstant, kMostlyInvalid };

struct ChannelFinding {
  HealthFinding kind = HealthFinding::kConstant;
  std::string channel;  ///< "" for the run-wide invalid share
  double value = 0.0;   ///< the held, sentinel or most extreme value; the invalid share
  double from_s = 0.0;  ///< the span the finding covers, s on the run's grid
  double to_s = 0.0;
  double share = 0.0;     ///< of the channel's valid samples (of all samples for kMostlyInvalid)
  std::string statement;  ///< one line, English
  /// False for kMostlyInvalid only: the run's valid rows still identify.
  bool blocks_models() const { return kind != HealthFinding::kMostlyInvalid; }
};

struct RunHealth {
  std::vector<ChannelFinding> findings;  ///< in channel order, run-wide last
  std::size_t channels = 0;              ///< channels examined
};

RunHealth channel_health(const RecordedRun& run, const HealthRules& rules = {});

/// The first blocking finding on a channel `model` reads with `effects` on this run (see
/// above), as its statement; nullopt when the model's data are healthy.
std::optional<std::string> unhealthy_reason(const RunHealth& health,
                                            const RunAnnouncement& announcement,
                                            const model::Model& model,
                                            const std::vector<std::string>& effects);

/// "not identified: <reason>", the line a reply prints in place of a model's table or verdict.
std::string not_identified(const std::string& reason);

}  // namespace dynid::ingest
