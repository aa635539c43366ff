#pragma once
// SimexAgainstIv: whether SIMEX may stand in for IV where the Durbin-Wu-Hausman test has
// rejected least squares (the publication rule, docs/ACCURACY.md).
//
// Why: both remove the bias the regressors' noise puts into least squares. IV needs no noise
// model; SIMEX needs the measured noise levels to be right and the noise white at the grid rate,
// and in return its std is about half IV's on the lateral model (the instruments are the rows
// 0.64 s away, weakly correlated with the regressors). Hausman's (1978) argument decides between
// them: where SIMEX's noise model holds both are consistent, so the difference IV - SIMEX of a
// parameter has mean 0, and a difference beyond its std says the noise model does not hold: IV
// stays. Its variance is not Hausman's std_IV^2 - std_SIMEX^2, which assumes SIMEX efficient
// against IV (measured on the second car's lateral runs: z's RMS 1.46, 6.6 % beyond the 1 %
// bound). SIMEX is least squares plus a correction whose sampling variation is second order
// (simex.hpp), so IV - SIMEX = (IV - LS) - correction, with variance difference_std^2 (the HAC
// variance of IV - LS, as the Durbin-Wu-Hausman test computes it) + mc^2 + level^2 (the
// correction's Monte Carlo and noise-level parts): z's RMS 1.12 there, 2.1 % beyond.
//
// Rule, for the model as a whole (one table, one estimator): SIMEX stands when it corrected the
// rows (some channel's noise reaches them), and for every parameter both estimate, its std is
// below IV's HAC std (else it gains nothing) and |IV - SIMEX| <= z sqrt(difference_std^2 + mc^2
// + level^2), z the two-sided normal quantile at family_level / (the number of those
// parameters) (Bonferroni).
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
  /// |z| = |IV - SIMEX| / sqrt(difference_std^2 + mc^2 + level^2).
  std::string deciding;
  double largest_z = 0.0;     ///< its |z| (NaN when SIMEX is not more precise there)

  /// One line an engineer reads: why SIMEX stands in for IV, or why IV stays.
  std::string statement() const;
};

/// Compares `simex` with `iv`, fitted on the same model and columns (else not compared).
SimexAgainstIv compare_simex_with_iv(const IvFit& iv, const SimexFit& simex, double family_level = 0.01);

}  // namespace dynid::residual
