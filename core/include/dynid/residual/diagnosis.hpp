#pragma once
// Diagnosis: the residual loop's judgement of one model on one stored run, in one of three
// verdicts, each said plainly:
//   adequate        the residual is at the noise floor (noise_floor.hpp): nothing to explain.
//   explained       above the floor, and a candidate effect is significant (effect_screen.hpp).
//   structure left  above the floor, and no candidate explains it: its signature says where to
//                   look (which channel and lag the residual correlates with, which time span of
//                   the run holds the most of it, which frequency). A significant candidate whose
//                   own model stays above its own floor explains a part only: it is named as such
//                   (Diagnosis::partial) and the verdict stays "structure left".
//
// The order is a closed test, so that the chance of an alarm on a run whose model lacks nothing
// is stated: the floor test comes first, at level floor.error_rate (default 0.025); only a
// residual above the floor is explained. The one other way a clean run gets an alarm is the
// hidden-structure test below, the better sensor's model against its own floor at the same
// level: together at most 0.05, one false alarm in 20 clean runs (the union bound). Candidates are
// then judged by the screen (HAC Wald test at family_error_rate / m, and a held-out gain), and a
// significant candidate must also be material: it takes its model to that model's floor, or
// removes at least the smallest excess the floor test resolves (upper_ratio - 1 of the floor's
// mean square, in some group); smaller structure is refused as immaterial, with its size, and
// is never the verdict's explanation nor an added term (diagnosis.cpp, "Materiality"). A
// significant candidate that takes the residual below the floor (its mean square under the
// floor's lower critical ratio) is refused: a missing effect adds to the noise, so removing it
// can bring the residual down to the floor, not under it. Only a better sensor of a declared
// signal does that (the accelerometer standing in for a noisy differentiated wheel speed:
// significant in every clean run, measured), and it is reported as such. A candidate can be
// significant on a run whose residual is at the floor; it is listed, the verdict stays
// "adequate", and the report says why.
//
// Structure the declared sensors' noise hides: a residual at the declared floor is still
// judged through the candidate the loop would accept (the same choice as above the floor). A
// model never fits worse with a column more, so when the accepted candidate's model is above
// its own floor while the declared one is at its floor, its floor is lower: the candidate
// reads a better sensor (the accelerometer for d_vx), and with it the residual shows structure
// the declared signal's noise covered. That structure is weighed like a candidate (Materiality):
// its mean square above the better sensor's floor, in units of the declared floor's, against
// the smallest excess the declared floor test resolves (upper_ratio - 1). Below that it is a
// note with its size (Diagnosis::hidden), never the verdict: the published parameters and
// their std come from the declared model, whose residual it changes by less than the floor's
// own uncertainty, and no candidate expresses it, so nothing says which parameter it would
// move (measured on an independent car's clean acceleration runs: 0.05 of the declared floor
// against 0.17-0.26 resolved, a few milliseconds between the torque and the acceleration,
// every run). At or above it the verdict is "structure left", the candidate named as the part
// it explains (Diagnosis::masked set). Its error rate: the accepted model's floor test, at the
// same level as the declared one's.
//
// A parameter's time course on the sharper rows: above the floor, when the accepted missing
// effect is a step or a drift of a parameter and a better sensor was passed over for it, the
// screen of that parameter's varying candidates is run again with the better sensor declared
// (its steps located on those rows), and its best is accepted instead when it keeps the
// parameters within their bounds there, is material and does not fit noise on the declared rows;
// the first choice is refused with the reason. Least
// squares' noise bias from a differentiated regressor differs between phases of a run, so on
// the noisy rows a step fits a phase boundary too (diagnosis.cpp, docs/RESIDUAL.md step 6).
//
// The signature's correlations: for every announced channel and its derivative (the model's
// measured side excepted: the residual is part of it) and the run's time (a drift), the
// normalised cross-correlation of the residual with the channel delayed by every lag of the
// decimated grid within +-max_lag_s (positive: the residual follows the channel). Its standard
// deviation under "no relation" is Bartlett's, sqrt((1 + 2 sum_j rho_rr(j) rho_uu(j)) / n), which
// holds for two autocorrelated series; a correlation is significant beyond the normal quantile
// 1 - error_rate / (2 M), M the number of correlations computed (Bonferroni).
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/effect_screen.hpp"
#include "dynid/residual/noise_floor.hpp"
#include "dynid/residual/sensor_agreement.hpp"
#include "dynid/residual/separability.hpp"

namespace dynid::residual {

struct CorrelationFinding {
  std::string group;
  std::string channel;      ///< a channel, d_<channel>, or "time"
  double lag_s = 0.0;       ///< > 0: the residual follows the channel by this long
  double correlation = 0.0;
  double bound = 0.0;       ///< the significance bound on |correlation| at this lag
};

/// One channel's cross-correlation with one group's residual at every lag tested, with its
/// significance bound (for the report's plots).
struct CorrelationCurve {
  std::string group;
  std::string channel;
  std::vector<double> lag_s;
  std::vector<double> correlation;
  std::vector<double> bound;
  double peak = 0.0;  ///< the largest |correlation| / bound over the lags (> 1: significant)
};

struct Signature {
  std::vector<CorrelationFinding> correlations;  ///< significant, strongest (|c| / bound) first, <= 8
  /// Per group, the kPlottedCurves channels whose correlation comes nearest its bound (or beyond
  /// it), strongest first: what the HTML report plots. Computed whatever the verdict.
  std::vector<CorrelationCurve> curves;
  std::string span_group;
  double span_start_s = 0.0;  ///< the cross-validation block whose residual RMS over the floor
  double span_end_s = 0.0;    ///< is highest
  double span_ratio = 0.0;    ///< that block's residual RMS / floor RMS
  double peak_frequency_hz = 0.0;  ///< of the residual's amplitude spectrum, DC excepted
};

enum class Verdict { kAdequate, kExplained, kStructureLeft };
const char* verdict_name(Verdict verdict);

struct DiagnosisOptions {
  ScreenOptions screen;
  NoiseFloorOptions floor;
  std::map<std::string, double> declared_noise;  ///< channel -> sigma, from the profile
  double max_lag_s = 1.0;
  double error_rate = 0.01;  ///< of the signature's correlations
};

/// Materiality of a significant candidate that is not a better sensor (diagnosis.cpp,
/// "Materiality"): in the group where it removes most against the floor test's resolution, the
/// in-sample mean square it removes, in units of the declared floor's mean square, and that
/// resolution (upper_ratio - 1 of the declared floor's test).
struct Materiality {
  std::string group;
  double removed = 0.0;
  double resolution = 0.0;
  bool reaches = false;  ///< the candidate's model passes its own floor test
  /// It explains the excess the floor test found, or removes at least what that test resolves.
  bool material() const { return reaches || removed >= resolution; }
};
/// `declared`: the declared model's floor; `extended`: the floor of the model with the candidate.
Materiality materiality(const NoiseFloor& declared, const NoiseFloor& extended);

/// Structure seen through a better sensor at the declared floor (above): `sensor` (the
/// candidate that reads it), in `group`, the better sensor's model's residual and floor RMS,
/// its excess over that floor in units of the declared floor's mean square (`share`), and the
/// smallest excess the declared floor test resolves (`resolution`, upper_ratio - 1).
struct HiddenStructure {
  std::string sensor;
  std::string group;
  double residual_rms = 0.0;
  double floor_rms = 0.0;
  double share = 0.0;
  double resolution = 0.0;
  bool material() const { return share >= resolution; }
  /// One sentence: what the sensor shows and why it is (or is not) material.
  std::string statement() const;
};
/// `declared`: the declared model's floor; `extended`: the better sensor's model's group
/// furthest above its own floor.
HiddenStructure hidden_structure(const std::string& sensor, const NoiseFloor& declared,
                                 const GroupFloor& extended);

struct RefusedCandidate {
  std::string effect;
  std::string reason;
};

struct Diagnosis {
  NoiseFloor floor;
  ScreenResult screen;
  /// The significant candidate the loop adds next: it explains the residual (kExplained), or a
  /// part of it (kStructureLeft with `partial` set).
  std::optional<CandidateScore> accepted;
  /// Set when the accepted candidate's model stays above its own noise floor: its group furthest
  /// above (ratio / upper_ratio). The verdict is then "structure left", the accepted candidate
  /// the part of it that can be explained.
  std::optional<GroupFloor> partial;
  /// The declared model's residual is at its floor, but the accepted candidate's model is above
  /// its own (lower) floor: structure the declared signals' noise hides (see above). Set with
  /// `partial`.
  bool masked = false;
  /// The accepted candidate lowers the noise floor: a better sensor of a declared signal (the
  /// accelerometer for d_vx), not a missing effect.
  bool better_sensor = false;
  /// Structure a better sensor shows under the declared floor but too small to matter (above):
  /// the note beside an "adequate" verdict.
  std::optional<HiddenStructure> hidden;
  /// Above the declared floor, the best candidate was a better sensor of a declared signal that
  /// agrees with the published parameters, its offsets nuisances (sensor_agreement.hpp): what it
  /// removes is that signal's own error, not a missing effect. It is refused, and the verdict is
  /// "adequate" when its model reaches its own floor (`sensor_reaches`), else "structure left"
  /// with what it leaves.
  std::optional<SensorAgreement> sensor_error;
  bool sensor_reaches = false;
  std::vector<RefusedCandidate> refused;  ///< significant candidates refused, with the reason
  Signature signature;
  /// Physical effects this run cannot rule out although they would bias the declared
  /// parameters beyond their std (separability.hpp), whatever the verdict: an effect that only
  /// rescales the fit (a head wind against drag and rolling resistance) leaves the residual at
  /// the floor.
  std::vector<Inseparable> inseparable;
  /// Declared parameters outside their model's physical bounds by more than two standard
  /// deviations (out_of_bounds), whatever the verdict: the model as declared is implausible on
  /// this run, and an effect it lacks (or a run that does not excite it) is the likely reason.
  std::vector<std::string> implausible;
  Verdict verdict = Verdict::kAdequate;
  /// One paragraph: the verdict and its evidence, and the declared parameters it finds implausible.
  std::string statement() const;
  /// The verdict and its evidence alone.
  std::string verdict_statement() const;
};

/// Why `value` +- `std` is implausible for `info`: outside its physical bounds by more than two
/// standard deviations (a parameter that may truly lie near a bound, a rolling resistance near 0,
/// falls on the wrong side of it by noise half the time); empty when it is not.
std::string out_of_bounds(const model::ParameterInfo& info, double value, double std);

/// Diagnoses `model` with its `declared` effects on `run` (assembled, not preprocessed: the
/// floor needs the raw samples). InputError as screen_effects.
Diagnosis diagnose(const model::Model& model, const std::vector<std::string>& declared,
                   const ingest::RecordedRun& run, const DiagnosisOptions& options = {});
/// The same with `segments` = preprocess_offline(run), for a caller that has them already (the
/// trace diagnoses one run round after round).
Diagnosis diagnose(const model::Model& model, const std::vector<std::string>& declared,
                   const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                   const DiagnosisOptions& options);
/// The same through `cache` (made on `run` and `segments`, used with the same options): the
/// channel noise, the noise draws and the floors of earlier diagnoses of the run are reused (the
/// trace's rounds: a round's declared floor is the floor of the candidate the round before added).
Diagnosis diagnose(const model::Model& model, const std::vector<std::string>& declared,
                   const ingest::RecordedRun& run,
                   const std::vector<ingest::PreprocessedSegment>& segments,
                   const DiagnosisOptions& options, FloorCache& cache);

}  // namespace dynid::residual
