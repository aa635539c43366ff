#pragma once
// Internal to the reports: one value as a text cell and as a JSON value. A value that is not
// finite (a parameter that is not identifiable, a test that did not run) is "-" in text and null
// in JSON, which has no NaN.
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace dynid::report::detail {

/// Six significant digits, or "-".
inline std::string number(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : "-"; }

/// The number, or null.
inline nlohmann::json finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace dynid::report::detail
