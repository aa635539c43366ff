#pragma once
// Command-line checks shared by dynid-car, dynid-server and dynid (CLI11 validators): every
// numeric option has stated limits, every input file must be a regular file, every vehicle id
// and run name follows the id rule. Header-only: the programs link CLI11, dynid_core does not.
//
// Contract: each validator refuses with a message naming the value (escaped) and the reason;
// CLI11 prefixes the option. within() refuses NaN and infinities, which CLI::Range and
// CLI::PositiveNumber let through (a NaN compares false with every bound), and a value that
// is not a number at all.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "dynid/error.hpp"
#include "dynid/input/ids.hpp"
#include "dynid/input/input_file.hpp"

namespace dynid::input {

inline std::string format_limit(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", value);
  return buf;
}

/// A finite number within [min, max].
inline CLI::Validator within(double min, double max) {
  const std::string range = "[" + format_limit(min) + ", " + format_limit(max) + "]";
  return CLI::Validator(
      [min, max, range](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value)) return "'" + printable(text) + "' is not a number";
        if (!std::isfinite(value) || value < min || value > max)
          return "'" + printable(text) + "' is outside " + range;
        return {};
      },
      "NUMBER in " + range);
}

/// A validator from a check that throws InputError: the error's text, or nothing.
template <typename Check>
CLI::Validator from_check(Check check, std::string description) {
  return CLI::Validator(
      [check](std::string& text) -> std::string {
        try {
          check(text);
        } catch (const InputError& e) {
          return e.what();
        }
        return {};
      },
      std::move(description));
}

/// A path the program reads: a regular file (check_input_file).
inline CLI::Validator input_file(std::string what) {
  return from_check([what](const std::string& path) { check_input_file(path, what); }, "FILE");
}

/// A path the program writes: absent, a regular file or a character device (check_output_file).
inline CLI::Validator output_file(std::string what) {
  return from_check([what](const std::string& path) { check_output_file(path, what); }, "FILE");
}

/// A vehicle id (what = "vehicle id") or run name (what = "run name"), as ids.hpp states.
inline CLI::Validator id(std::string what) {
  return CLI::Validator(
      [what](std::string& text) -> std::string {
        const std::string problem = id_problem(text);
        return problem.empty() ? std::string() : what + " '" + printable(text) + "' " + problem;
      },
      "ID");
}

}  // namespace dynid::input
