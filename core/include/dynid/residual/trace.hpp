#pragma once
// Trace: the residual loop as one command (issue 15; DESIGN.md "Residual loop"): diagnose the
// model (diagnosis.hpp), add the candidate that explains its residual, diagnose again, until
//   - the model is adequate (its residual at the noise floor),
//   - structure is left that no candidate explains (its signature says where to look),
//   - the accepted candidate would make the held-out residual worse, or take a parameter out of
//     the physical bounds its model declares (model::ParameterInfo) by more than two of its
//     standard deviations: refused, with the reason,
//   - or max_rounds effects were added.
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

/// Runs the loop on `run` (assembled; diagnosis.hpp). InputError as diagnose.
Trace trace(const model::Model& model, const std::vector<std::string>& declared,
            const ingest::RecordedRun& run, const TraceOptions& options = {});

}  // namespace dynid::residual
