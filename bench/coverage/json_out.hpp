#pragma once
// --json FILE: every seed's values (manoeuvre, seed, run time, error text; per parameter the
// truth, the value and both std, the HAC fit's own value; the IV value, its two std, the model's
// DWH verdict, instruments' F and any refusal), and the summary rows, for plots and for checking
// the tables by hand.
#include <string>
#include <vector>

#include "measure.hpp"
#include "summary.hpp"

namespace dynid::benchcoverage {

/// Writes the file; false (with a message on stderr) when it cannot.
bool write_json(const std::string& path, const std::vector<SeedRun>& runs, const std::vector<ParameterCoverage>& rows,
                double seconds);

}  // namespace dynid::benchcoverage
