#pragma once
// Text for people on a terminal: every line the product prints outside a table fits in
// kTextWidth columns, so that an answer reads without a horizontal scroll or a terminal's own
// wrap through the middle of a word. Tables keep their columns (a cell is not wrapped).
//
// Contract: pure functions of their arguments; they never throw beyond std::bad_alloc.
#include <cstddef>
#include <string>
#include <vector>

namespace dynid::report {

inline constexpr std::size_t kTextWidth = 100;

/// `head` then `text` on the first line, broken at spaces so that no line is wider than `width`
/// columns; the following lines are indented by `indent` spaces. A word longer than a line
/// stays whole on a line of its own. Every line ends with '\n'.
std::string wrap_text(const std::string& head, const std::string& text, std::size_t indent,
                      std::size_t width = kTextWidth);

/// The clauses of a statement joined by "; " outside parentheses (a verdict and its evidence:
/// "explained: above the noise floor (a; b); road_grade explains it" has two).
std::vector<std::string> clauses(const std::string& statement);

/// A statement for reading: its first clause after `head`, every further clause on a line of its
/// own, each wrapped as wrap_text() with `indent`.
std::string wrap_clauses(const std::string& head, const std::string& statement, std::size_t indent);

}  // namespace dynid::report
