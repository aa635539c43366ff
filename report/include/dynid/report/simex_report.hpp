#pragma once
// The SIMEX correction of one model on one run (residual/simex.hpp) as engineers read it
// (`dynid simex`): per parameter the least-squares value and its HAC std, the value corrected
// for the measured sensor noise with its std and that std's parts (Monte Carlo, the noise
// levels' own uncertainty), the correction in stds, and which of the two the server publishes
// where the bias test does not send the model to IV: `by_simex` marks those rows, as
// residual::publish (residual/publication.hpp) decides them; the report does not re-decide.
// Text and JSON.
#include <string>
#include <vector>

#include "dynid/residual/simex.hpp"

namespace dynid::report {

/// `by_simex`: one flag per parameter of `fit` (InputError otherwise).
std::string format_simex_text(const residual::SimexFit& fit, const std::vector<bool>& by_simex);
std::string simex_json(const residual::SimexFit& fit, const std::vector<bool>& by_simex);

}  // namespace dynid::report
