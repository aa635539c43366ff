#pragma once
// SensorAgreement: whether a better sensor of a declared signal (the accelerometer for the
// differentiated wheel speed: a candidate whose model's noise floor is lower than the declared
// one's, diagnosis.hpp) agrees with the parameters the product publishes, once the sensor's
// per-run offset is estimated as a nuisance.
//
// Why: a real accelerometer reads a per-run offset (mount angle, zero drift). Read in place of
// d_vx, its offset o enters the longitudinal rows as mass x o, a constant force: exactly the
// rolling resistance's column on a run that never reverses, so the fit moves the rolling
// resistance by mass x o (an independent car's clean run: 161 -> 137 N for o = 0.0125 m/s^2,
// truth 153). That move is the sensor's, not the car's. And the declared least-squares values
// are biased by the noise in d_vx (errors in variables); the product publishes IV where the
// Durbin-Wu-Hausman test rejects least squares (publication.hpp). A better sensor is therefore
// judged against the published values, with its offsets as nuisances, never against least
// squares' own bias (issue 34, item 2).
//
// The nuisance fit, exact for a model linear in the sensor (every model here is): the model with
// the candidate is fitted with each mounted sensor it reads (an accelerometer or rate sensor,
// sensor_offset.hpp) shifted by -delta, 0 and +delta. Its weighted residual sum of squares is a
// parabola in the offset, RSS(o) = RSS(o_hat) + c (o - o_hat)^2, and every parameter a line,
// theta(o) = theta(0) + s o. Profiling the offset out (Frisch-Waugh) gives the joint estimate
// theta(o_hat) with var = var(theta | o) + s^2 var(o_hat), var(o_hat) = s_rho^2 / c. Where c is 0
// (the offset is a column of the model, as in the longitudinal rows), the parameters that move
// with it (s != 0) are not identifiable beside the nuisance: they are left out of the
// comparison, by name; the others do not depend on the offset and are compared as they are.
// The groups' weights are those of the declared fit (one scale for every fit): exact for one
// equation group; for several, to the first order of the weights' own change.
//
// The comparison is Hausman's for a sharper estimator: under "the sensor is the declared signal
// read better", both estimate the same parameters and the better sensor's are the efficient ones,
// so the difference's variance is var_published - var_with_sensor (the sum where that is not
// positive: conservative). The sensor agrees when no compared parameter moves by more than the
// normal quantile at 1 % over the compared parameters (Bonferroni): hausman_distance and
// hausman_bound (effect_comparison.hpp), the rule of trace.hpp.
// Published values: IV's (HAC std) where IV replaces least squares on the declared model, else
// least squares'. SIMEX, which publication.hpp may put in IV's place, is not computed here: it
// needs the noise floor's draws; IV is its reference (simex_against_iv.hpp).
//
// Contract: pure; InputError from the fits propagates (the caller decides what it cannot tell).
#include <optional>
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::residual {

struct ComparedParameter {
  std::string name;
  std::string unit;
  double published = 0.0;
  double published_std = 0.0;
  double with_sensor = 0.0;      ///< joint estimate with the offsets profiled out
  double with_sensor_std = 0.0;  ///< its std, the offsets' uncertainty included
  double moved = 0.0;            ///< |difference| in std of the difference
};

struct SensorAgreement {
  std::string effect;                ///< the better sensor's candidate
  std::vector<std::string> offsets;  ///< the mounted sensors whose offsets were nuisances
  std::string estimator;             ///< of the published values: "IV" or "least squares"
  std::vector<ComparedParameter> compared;
  /// Parameters left out: they move with an offset that the model cannot tell from them.
  std::vector<std::string> not_compared;
  double bound = 0.0;  ///< the normal quantile at 1 % over the compared parameters

  /// The parameter that moved most (null when none was compared).
  const ComparedParameter* largest() const;
  /// At least one parameter compared and none moved beyond the bound.
  bool agrees() const;
  /// "ax (road_grade_accelerometer), its offset a nuisance, agrees with the published (IV)
  /// parameters: largest move mass 1459 -> 1458 kg, 0.87 std of the difference (at most 2.94 at
  /// 1 % over 2 parameters); not compared: rolling_resistance (the offset of ax takes its place)"
  std::string statement() const;
};

/// The agreement of `effect` (a candidate of `model`, reading `sensors`) with the published
/// values of `model` with `declared` (above). `fit`: the rows' options (series unused);
/// `preprocessing`: the run's, for IV's lag.
SensorAgreement sensor_agreement(const model::Model& model,
                                 const std::vector<std::string>& declared,
                                 const std::string& effect, const std::vector<std::string>& sensors,
                                 const std::vector<ingest::PreprocessedSegment>& run,
                                 double sample_rate_hz, int odmf, const FitOptions& fit,
                                 const ingest::Preprocessing& preprocessing);

}  // namespace dynid::residual
