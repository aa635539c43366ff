#pragma once
// SimexAgainstIv: whether SIMEX may stand in for IV where the Durbin-Wu-Hausman test has
// rejected least squares (the publication rule, docs/ACCURACY.md).
//
// Why: both remove the bias the regressors' noise puts into least squares. IV needs no noise
// model; SIMEX needs the measured noise levels to be right and the noise white at the grid rate,
// and in return its std is about half IV's on the lateral model (the instruments are the rows
// 0.64 s away, weakly correlated with the regressors). Hausman's (1978) argument decides between
// them: where SIMEX's noise model holds both are consistent and SIMEX is the more efficient, so
// the difference IV - SIMEX of a parameter has variance std_IV^2 - std_SIMEX^2 and mean 0. A
// difference beyond that says the noise model does not hold, and IV stays.
//
// Rule, for the model as a whole (one table, one estimator): SIMEX stands when it corrected the
// rows (some channel's noise reaches them), and for every parameter both estimate, its std is
// below IV's HAC std and |IV - SIMEX| <= z sqrt(std_IV^2 - std_SIMEX^2), z the two-sided normal
// quantile at family_level / (the number of those parameters) (Bonferroni: the family's error
// rate, refusing a right SIMEX, is at most family_level). A parameter whose SIMEX std is not
// below IV's gains nothing from SIMEX and has no Hausman variance: IV stays.
#include <string>

#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/simex.hpp"

namespace dynid::residual {

struct SimexAgainstIv {
  bool compared = false;      ///< same columns, IV estimated, SIMEX corrected, a parameter in both
  bool simex_stands = false;  ///< compared, and SIMEX may be published in IV's place
  double level = 0.0;         ///< per parameter: family_level / parameters compared
  int parameters = 0;         ///< compared
  /// The parameter that decided: the first one SIMEX is not more precise for, else the largest
  /// |z| = |IV - SIMEX| / sqrt(std_IV^2 - std_SIMEX^2).
  std::string deciding;
  double largest_z = 0.0;     ///< its |z| (NaN when SIMEX is not more precise there)

  /// One line an engineer reads: why SIMEX stands in for IV, or why IV stays.
  std::string statement() const;
};

/// Compares `simex` with `iv`, fitted on the same model and columns (else not compared).
SimexAgainstIv compare_simex_with_iv(const IvFit& iv, const SimexFit& simex, double family_level = 0.01);

}  // namespace dynid::residual
