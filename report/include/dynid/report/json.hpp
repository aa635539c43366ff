#pragma once
// JSON text for replies and --json output: just what dynid writes (no parser). Numbers are
// written with 17 significant digits, so a reader gets the double back bit for bit; NaN and
// infinities, which JSON lacks, are written as null.
#include <string>
#include <string_view>

namespace dynid::report {

/// `text` as a JSON string literal, quotes included (control characters escaped).
std::string json_string(std::string_view text);
/// `value` as a JSON number (round-trip exact), or null when it is not finite.
std::string json_number(double value);

}  // namespace dynid::report
