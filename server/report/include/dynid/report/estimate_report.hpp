#pragma once
// The estimate table as engineers read it: one line per parameter (name, unit, value, standard
// deviation, relative standard deviation %, status identified/regrouped/dependent/eliminated,
// the regrouping relation) and the fit's figures (rows, sigma, cond, residual RMS, per group).
//
// format_estimate_text(): fixed-width text, values with 6 significant digits, "-" for values
// that are not identifiable (NaN). estimate_json(): every field, numbers exact (json.hpp).
#include <string>
#include <vector>

#include "dynid/dds/estimate_table.hpp"

namespace dynid::report {

std::string format_estimate_text(const dds::EstimateTable& table);
std::string estimate_json(const dds::EstimateTable& table);
/// A JSON array of tables.
std::string estimates_json(const std::vector<dds::EstimateTable>& tables);
/// Status names as printed: "identified", "regrouped", "dependent", "eliminated".
const char* status_name(ls::ParameterStatus status);

}  // namespace dynid::report
