#pragma once
// The estimate table as engineers read it: one line per parameter (name, unit, value, standard
// deviation, relative standard deviation %, status, the regrouping relation, the status' reason)
// and the fit's figures (rows, sigma, cond, residual RMS, per group). Statuses:
// identified, poorly identified, not excited, implausible (model/parameter_status.hpp), and
// regrouped, dependent, eliminated (ls/base_parameters.hpp). A model the source does not
// excite at all (EstimateTable::not_excited) prints one line saying what would excite it
// instead of the table; its JSON keeps every field.
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
/// Status names as printed: "identified", "regrouped", "dependent", "eliminated",
/// "poorly identified", "not excited", "implausible".
const char* status_name(ls::ParameterStatus status);

}  // namespace dynid::report
