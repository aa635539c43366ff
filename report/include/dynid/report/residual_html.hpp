#pragma once
// residual_html(): the residual loop's report as one self-contained HTML page (no external file:
// the plots are PNG data URIs), for a browser or an e-mail. Plots are drawn by gnuplot
// (pngcairo): per equation group, the residual against time (before, and after the added
// effect; for an added step located by the screen, its time marked and its 95 % set shaded), the
// residual against the effect's fitted contribution (a missing effect lies on the diagonal), and
// the amplitude spectra of the residuals; with a diagnosis, per group the residual's
// cross-correlation with the channels that come nearest their significance bound, against the
// lag, with those bounds (Signature::curves), and the floor test at every time scale (the rows'
// mean square and the block sums over the floor's, with each critical ratio). Tables: the
// verdict, the ranking, the before/after parameters and residual figures.
//
// The page marks itself when the browser has decoded its images: <body data-images="k/n">
// (k of n images with a natural width), so a test in a real browser can check it.
//
// Errors: std::runtime_error naming gnuplot when it cannot be run or fails (its stderr is
// quoted); nothing is written then.
#include <optional>
#include <string>

#include "dynid/residual/diagnosis.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/effect_screen.hpp"

namespace dynid::report {

struct HtmlReportInput {
  std::string title;                                 ///< e.g. "dynid-testcar / run-17"
  const residual::ScreenResult* screen = nullptr;    ///< the ranking, if any
  const residual::EffectComparison* comparison = nullptr;  ///< the added effect, if any
  /// The added effect as the screen found it, if known: a located step is marked on the plots.
  const residual::CandidateScore* added = nullptr;
  std::string gnuplot = "gnuplot";                   ///< the program (PATH is searched)
  /// The diagnosis the screen belongs to, if any: its statement, correlation and floor plots.
  const residual::Diagnosis* diagnosis = nullptr;
};

std::string residual_html(const HtmlReportInput& input);

/// `text` with the characters HTML gives meaning to (< > & ") escaped.
std::string html_escape(const std::string& text);

}  // namespace dynid::report
