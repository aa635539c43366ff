#pragma once
// The residual loop as engineers read it (core/residual): the candidate ranking with its
// verdict, and the before/after table of an added effect, as fixed-width text (dynid residual,
// dynid add-effect, the tests' printouts) and as one self-contained HTML page with plots
// (residual_html.hpp).
#include <cstddef>
#include <string>

#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/effect_screen.hpp"

namespace dynid::report {

/// The ranking (the first `top` tested candidates, then how many were not tested and why, one
/// line per reason) and the verdict.
std::string format_screen_text(const residual::ScreenResult& screen, std::size_t top = 15);

/// Parameters before and after with standard deviations (and errors against the truth where
/// known), per group the residual RMS and relative norm in sample and held out, the weighted
/// drops. A road profile's knots are summarised in one line, not listed.
std::string format_comparison_text(const residual::EffectComparison& comparison);

}  // namespace dynid::report
