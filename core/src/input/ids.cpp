#include "dynid/input/ids.hpp"

#include <cstdio>

#include "dynid/error.hpp"

namespace dynid::input {
namespace {

bool alphanumeric(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

bool id_character(char c) { return alphanumeric(c) || c == '.' || c == '_' || c == '-'; }

std::string escaped(char c) {
  if (c == '\\' || c == '\'') return std::string("\\") + c;
  if (c >= 0x20 && c < 0x7f) return std::string(1, c);
  char buf[8];
  std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(static_cast<unsigned char>(c)));
  return buf;
}

}  // namespace

std::string id_problem(std::string_view id) {
  if (id.empty()) return "is empty";
  if (id.size() > kMaxIdLength)
    return "is " + std::to_string(id.size()) + " characters long, at most " + std::to_string(kMaxIdLength) +
           " are allowed";
  if (!alphanumeric(id.front()))
    return "starts with '" + escaped(id.front()) + "': the first character must be a letter or a digit";
  for (std::size_t i = 0; i < id.size(); ++i)
    if (!id_character(id[i]))
      return "character " + std::to_string(i + 1) + " '" + escaped(id[i]) +
             "' is not allowed (only A-Z a-z 0-9 . _ -)";
  return "";
}

void check_id(std::string_view what, std::string_view id) {
  const std::string problem = id_problem(id);
  if (!problem.empty()) throw InputError(std::string(what) + " '" + printable(id) + "' " + problem);
}

std::string printable(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (out.size() >= kMaxShown) return out + "...";
    out += escaped(text[i]);
  }
  return out;
}

std::string printable_text(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) out += c == '\\' || c == '\'' ? std::string(1, c) : escaped(c);
  return out;
}

}  // namespace dynid::input
