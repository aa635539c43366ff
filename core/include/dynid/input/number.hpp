#pragma once
// Numbers in text the programs are given (request arguments, effect names): the whole text must
// be the number, in the C locale, with no blank around it (std::from_chars). For arguments that
// are not command-line options (those go through tools/options' validators, option_checks.hpp).
//
// Contract: parse_finite() is the value when `text` is exactly a finite decimal number
// (std::nullopt otherwise: empty, trailing text, "nan", "inf", out of range); parse_integer()
// likewise for a decimal integer that fits in long long.
#include <optional>
#include <string_view>

namespace dynid::input {

std::optional<double> parse_finite(std::string_view text);
std::optional<long long> parse_integer(std::string_view text);

}  // namespace dynid::input
