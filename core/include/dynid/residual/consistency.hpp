#pragma once
// Consistency: what two models of one run, or a model and a known value, say about the same
// parameter (issue 15: "some missing effects leave no trace in any residual: a torque signal that
// reads 7 % high, or a rolling radius 3 % off, rescale every parameter of a model exactly and the
// residual only scales. They show up as disagreement").
//
// Compared: every pair of parameters of two models of the run that measure one physical quantity
// of the car (model::ParameterInfo::quantity: the wheel-torque and the engine-torque
// longitudinal models share mass, SCx, rolling resistance; the clutch model and the
// engine-torque one the ECU's torque offset), never two parameters that only share a name (the
// ax and the ay accelerometers' scales; the clutch model's engine inertia and the locked
// driveline's, which includes the gearbox input); and every parameter for which the engineer
// gives a reference value (the weighed mass), under its quantity's name when it declares one
// (ParameterInfo::reference_key: "ax_sensor_scale", not every "sensor_scale"). A parameter the
// run does not excite (its std at least its typical magnitude, model/parameter_status.hpp) is
// compared with nothing: its value is whatever the other columns leave. Nor is one whose
// relative std exceeds DYCARO's quality limit (StatusRules::poor_relative_std_percent, 10 %;
// listed in Consistency::not_compared with the reason): its column's signal is weak against the
// noise in it, and least squares' errors-in-variables attenuation, the share of a noisy
// column's variance that is noise, is then not bounded by the std, while the bias test has too
// little signal to reject least squares (on an independent car's launches the engine-torque
// model's mass read 430-977 kg at 13-42 % relative std, 3-5.5 std from the wheel-torque
// model's 1450 kg on 5 of 10 clean launches). The test of one comparison:
// z = (a - b) / sqrt(sa^2 + sb^2) (a reference has no std), two-sided, at family_error_rate / m
// (Bonferroni over the m comparisons, so that a run whose models agree raises an alarm at most that
// often). Ignoring the correlation of two fits of one run is conservative: they share the run's
// noise, which makes var(a - b) smaller than sa^2 + sb^2, not larger.
//
// The standard deviations are HAC ones (Newey-West on the rows' scores, hac_wald.hpp): the rows
// are low-passed and decimated, and DYCARO's sigma^2 (W'W)^-1 counts every row as independent,
// which would call a 1 % difference of two honest fits significant.
//
// The values are the published estimator's where it is instrumental variables (publication.hpp,
// rule 1: IV replaces least squares when its Durbin-Wu-Hausman test rejects them), with IV's HAC
// std (with_instruments). Least squares' errors-in-variables bias (a noisy differentiated wheel
// speed in a column) differs between two models of one run, whose rows and noisy columns differ,
// so two honest least-squares fits disagree by it: measured on an independent car, the wheel-
// and engine-torque models' masses 1 % apart (z = 3-9) on every acceleration and launch run.
//
// Traced to a scale: when models disagree and every parameter they share disagrees by one
// common ratio (the log-ratios' homogeneity chi-square test does not reject at the same level),
// the disagreement has the signature of a scale error of one model's measured side (its torque
// sensor, or the rolling radius or gear ratio its force is computed with): a finding like any
// other, with the ratio and its std. A reference value, when given, says which side is off.
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::residual {

/// One model's estimate on a run, with HAC standard deviations.
struct ModelParameters {
  std::string model;
  std::vector<std::string> measured_side;  ///< Model::measured_side()
  std::vector<model::ParameterInfo> parameters;
  Eigen::VectorXd value;  ///< NaN: not identifiable
  Eigen::VectorXd std;    ///< HAC; NaN where the value is
  std::string estimator = "least squares";  ///< or "IV" (with_instruments)
};

/// `model` with `effects` fitted on `run` (preprocessed segments), with HAC standard deviations.
/// InputError as fit_model.
ModelParameters hac_parameters(const model::Model& model, const std::vector<std::string>& effects,
                               const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                               int odmf, const FitOptions& options = {});

/// `ls` with `iv`'s values and HAC std on every parameter both estimate, when `iv` is a fit of
/// the same columns that replaces least squares (IvFit::replaces_least_squares); else `ls`
/// unchanged.
ModelParameters with_instruments(ModelParameters ls, const IvFit& iv);

/// What the check weighs for `model` with `effects` on `run` (preprocessed segments of the run
/// `announcement` announces): hac_parameters, with IV's values where IV replaces least squares
/// (with_instruments; where no IV fit of these rows can be made, least squares'). The one home of
/// that choice: the server's consistency request and bench/trace call it. InputError as
/// hac_parameters.
ModelParameters compared_parameters(const model::Model& model,
                                    const std::vector<std::string>& effects,
                                    const std::vector<ingest::PreprocessedSegment>& run,
                                    const ingest::RunAnnouncement& announcement);

inline constexpr const char* kReference = "reference";

struct ParameterAgreement {
  std::string parameter;
  std::string unit;
  std::string first;   ///< a model
  std::string second;  ///< another model, or kReference
  std::string first_estimator,
      second_estimator;  ///< ModelParameters::estimator; empty for a reference
  double first_value = 0.0, first_std = 0.0;
  double second_value = 0.0, second_std = 0.0;  ///< a reference's std is 0
  double z = 0.0;
  double p_value = 1.0;
  bool significant = false;
};

struct ScaleFinding {
  std::string first, second;  ///< models (second may be kReference)
  std::vector<std::string> parameters;  ///< the shared parameters the ratio rests on
  double ratio = 1.0;      ///< first's parameters over second's
  double ratio_std = 0.0;
  double homogeneity_p = 1.0;  ///< one common ratio for all of them (1 with one parameter)
  bool one_ratio = true;       ///< homogeneity not rejected
  std::string off;             ///< the model a reference shows to be off, empty when unknown
  std::string statement;
};

struct Consistency {
  std::vector<ParameterAgreement> comparisons;
  /// Parameters that declare a shared quantity or have a reference value but were not compared
  /// for their precision (above), each "model: parameter = value +- std (x % relative std)".
  std::vector<std::string> not_compared;
  int tests = 0;
  double level = 0.0;  ///< family_error_rate / tests
  std::vector<ScaleFinding> scales;  ///< one per pair with a significant disagreement
  bool consistent() const;
  /// One paragraph.
  std::string statement() const;
};

Consistency check_consistency(const std::vector<ModelParameters>& models,
                              const std::map<std::string, double>& reference, double family_error_rate = 0.01);

}  // namespace dynid::residual
