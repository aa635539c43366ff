#pragma once
// The residual loop as engineers read it (core/residual): the diagnosis (noise floor, ranking,
// verdict), the before/after table of an added effect, and the loop's rounds (dynid trace), as
// fixed-width text (dynid residual, add-effect, trace; the tests' printouts), as JSON for tools
// (--json), and as one self-contained HTML page with plots (residual_html.hpp).
#include <cstddef>
#include <string>
#include <vector>

#include "dynid/residual/consistency.hpp"
#include "dynid/residual/diagnosis.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/effect_screen.hpp"
#include "dynid/residual/trace.hpp"

namespace dynid::report {

/// The ranking (the first `top` tested candidates, then how many were not tested and why, one
/// line per reason) and the verdict.
std::string format_screen_text(const residual::ScreenResult& screen, std::size_t top = 15);

/// Parameters before and after with standard deviations (and errors against the truth where
/// known), per group the residual RMS and relative norm in sample and held out, the weighted
/// drops. A road profile's knots are summarised in one line, not listed.
std::string format_comparison_text(const residual::EffectComparison& comparison);

/// The diagnosis: per group the residual against its noise floor, the channels whose noise makes
/// the floor, the ranking (format_screen_text), refused candidates, the signature's
/// correlations, and the verdict's statement.
std::string format_diagnosis_text(const residual::Diagnosis& diagnosis, std::size_t top = 10);

/// Every round of the loop (its diagnosis's statement, the effect it added with the before/after
/// table) and why it stopped.
std::string format_trace_text(const residual::Trace& trace);

/// The consistency check of a run's models (dynid consistency): first the answer (consistent, or
/// each scale finding on its own line), then every comparison (parameter, the two sides with
/// their HAC std, z, significant), and the parameters not compared and the models left out with
/// the reason; no line but the table's wider than text_wrap.hpp's width.
std::string format_consistency_text(const residual::Consistency& consistency, const std::vector<std::string>& left_out);

/// The same as JSON objects, for tools (nlohmann::json; NaN and infinities as null). The added
/// effect's fitted contribution row by row (`effect_series`: a run's worth of numbers) only with
/// `series`; without, the key is absent.
std::string diagnosis_json(const residual::Diagnosis& diagnosis);
std::string comparison_json(const residual::EffectComparison& comparison, bool series = false);
std::string trace_json(const residual::Trace& trace, bool series = false);
std::string consistency_json(const residual::Consistency& consistency, const std::vector<std::string>& left_out);

}  // namespace dynid::report
