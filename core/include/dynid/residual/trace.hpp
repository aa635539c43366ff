#pragma once
// Trace: the residual loop as one command (issue 15; DESIGN.md "Residual loop"): diagnose the
// model (diagnosis.hpp), add the candidate that explains its residual, diagnose again, until
//   - the model is adequate (its residual at the noise floor),
//   - structure is left that no candidate explains (its signature says where to look),
//   - the accepted candidate would make the held-out residual worse, or take a parameter out of
//     the physical bounds its model declares (model::ParameterInfo) by more than two of its
//     standard deviations: refused, with the reason,
//   - the accepted candidate is a better sensor of a declared signal taken at the declared
//     floor (Diagnosis::masked) and moves a declared parameter beyond what its lower noise
//     explains: refused (Hausman's test, below),
//   - the accepted candidate is a dictionary term that explains a part only
//     (Diagnosis::partial; not a better sensor), and it moves a declared parameter beyond
//     Hausman's bound (below, with the variance std_after^2 - std_before^2 of a column more):
//     refused (a generic part is no license to move the physics),
//   - or max_rounds effects were added.
//
// Why a generic part may not move the physics: a dictionary term (a lag, a derivative, a
// product of channels) names no mechanism; adding its column leaves the declared parameters
// where they were, up to the variance the column adds (the nested fits' Hausman difference),
// unless it takes some of the declared physics over. With the model still above its floor,
// nothing then says the moved values are nearer the car's: on an independent car's
// load-sensitive tyres, four dictionary terms added one after another took the yaw inertia from
// -1 % to -47 % of its truth (the first moved a cornering stiffness 12 std of the difference). A
// named mechanism may move them even as a part: its shift is the omitted-variable correction
// when the mechanism is real (the same car's head wind: linear_drag, partial beside other
// structure, took SCx from +34 % to +0.1 % of its truth while moving the mass 26 such std). A
// term that takes the model to its floor is an explanation, not a part.
//
// The better sensor's test: at the declared floor the declared model lacks nothing its noise
// lets one see, so a sensor that is only less noisy (the accelerometer for the wheel-speed
// derivative) sharpens the parameters without moving them: under that hypothesis the declared
// fit is consistent and the extended one efficient, and each parameter's change d has variance
// std_before^2 - std_after^2 (Hausman 1978). A change beyond the normal quantile at 1 % over
// the declared parameters (Bonferroni) says the sensor differs from the declared signal
// systematically (its mounting, the body's pitch it reads), not only in noise: on our own
// simulator's hill run, after the GNSS grade, the accelerometer moved the rolling resistance by
// 4.4 of those std (206 -> 109 N, truth 216) and SCx by 3.1. Above the floor the test does not
// apply: there the declared model is misspecified and any candidate that explains the residual
// moves its parameters.
// Each round keeps its diagnosis and, when an effect was added, the before/after comparison
// (effect_comparison.hpp: parameters with std before and after, residual RMS in sample and held
// out per group, errors against `reference` values where given).
//
// Why the loop stops on the first refusal rather than trying the next candidate: the next one
// was ranked below a candidate the data prefer; adding it would explain the residual with the
// wrong physics. The refusal and the candidates are in the report for the engineer to judge.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/diagnosis.hpp"
#include "dynid/residual/effect_comparison.hpp"

namespace dynid::residual {

struct TraceRound {
  std::vector<std::string> effects;  ///< the model's effects when diagnosed
  Diagnosis diagnosis;
  std::optional<EffectComparison> added;  ///< the accepted candidate, added
};

struct TraceOptions {
  DiagnosisOptions diagnosis;
  int max_rounds = 4;  ///< effects added at most
  /// Known values (parameter name -> value, e.g. the weighed mass): errors before and after.
  std::map<std::string, double> reference;
};

struct Trace {
  std::string model;
  std::vector<std::string> declared;
  std::vector<TraceRound> rounds;
  std::string stopped;  ///< why the loop stopped, one sentence
  /// The effects the loop added, in order.
  std::vector<std::string> added() const;
};

/// Hausman's test of a better sensor (above): empty when every declared parameter of `c` (those
/// with a finite value before) moved within the normal quantile at 1 % over them (Bonferroni)
/// of std_before^2 - std_after^2 (their sum where the sensor did not sharpen it); else the
/// refusal, naming the parameter that moved most.
std::string better_sensor_refusal(const EffectComparison& c);

/// The same test for a dictionary term that explains a part only (above): a column more, so the
/// difference's variance is std_after^2 - std_before^2 (the sum where that is not positive);
/// empty when every declared parameter moved within the bound, else the refusal.
std::string partial_refusal(const EffectComparison& c);

/// Runs the loop on `run` (assembled; diagnosis.hpp). InputError as diagnose.
Trace trace(const model::Model& model, const std::vector<std::string>& declared,
            const ingest::RecordedRun& run, const TraceOptions& options = {});

}  // namespace dynid::residual
