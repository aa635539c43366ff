#include "dynid/report/text_wrap.hpp"

namespace dynid::report {

std::string wrap_text(const std::string& head, const std::string& text, std::size_t indent,
                      std::size_t width) {
  std::string out = head;
  std::size_t column = head.size();
  // Whether the line holds anything but its indent (a word may only move to a new line then),
  // and whether a word is on it (the next is put after a space).
  bool content = head.find_first_not_of(' ') != std::string::npos, word_on_line = false;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    if (const std::size_t word = end - start; word > 0) {
      if (content && column + (word_on_line ? 1 : 0) + word > width) {
        out += "\n" + std::string(indent, ' ');
        column = indent;
        word_on_line = false;
      }
      if (word_on_line) out += ' ', ++column;
      out.append(text, start, word);
      column += word;
      content = word_on_line = true;
    }
    start = end + 1;
  }
  return out + "\n";
}

std::vector<std::string> clauses(const std::string& statement) {
  std::vector<std::string> out;
  int depth = 0;
  std::size_t start = 0;
  for (std::size_t k = 0; k < statement.size(); ++k) {
    const char c = statement[k];
    if (c == '(') ++depth;
    if (c == ')' && depth > 0) --depth;
    if (depth == 0 && c == ';' && k + 1 < statement.size() && statement[k + 1] == ' ') {
      out.push_back(statement.substr(start, k - start));
      start = k + 2;
    }
  }
  if (start < statement.size() || out.empty()) out.push_back(statement.substr(start));
  return out;
}

std::string wrap_clauses(const std::string& head, const std::string& statement,
                         std::size_t indent) {
  const std::vector<std::string> parts = clauses(statement);
  std::string out = wrap_text(head, parts.front(), indent);
  for (std::size_t k = 1; k < parts.size(); ++k)
    out += wrap_text(std::string(indent, ' '), parts[k], indent + 2);
  return out;
}

}  // namespace dynid::report
