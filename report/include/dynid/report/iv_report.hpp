#pragma once
// The instrumental-variable estimate of one model on one run (residual/iv_fit.hpp) as engineers
// read it (`dynid iv`): per parameter the least-squares and IV values side by side with their
// standard deviations and how far apart they are, the instruments' strength, the
// Durbin-Wu-Hausman test and the one-line verdict (IvFit::statement()). Text and JSON.
#include <string>

#include "dynid/residual/iv_fit.hpp"

namespace dynid::report {

std::string format_iv_text(const residual::IvFit& fit);
std::string iv_json(const residual::IvFit& fit);

}  // namespace dynid::report
