#include "dbc_lexer.hpp"

#include <dynid/error.hpp>

namespace dynid::can::detail {
namespace {

bool is_ident_start(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_';
}
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_ident_char(char c) { return is_ident_start(c) || is_digit(c); }

class Lexer {
 public:
  Lexer(std::string_view text, std::string_view name) : text_(text), name_(name) {}

  std::vector<Token> run() {
    std::vector<Token> out;
    while (skip_space()) out.push_back(next());
    Token end;
    end.line = line_;
    end.opens_line = true;
    out.push_back(end);
    return out;
  }

 private:
  // A line ends with LF, CRLF or a lone CR (old Mac files): true when text_[i] ends one. In CRLF
  // the LF ends the line.
  bool ends_line(std::size_t i) const {
    return text_[i] == '\n' ||
           (text_[i] == '\r' && (i + 1 >= text_.size() || text_[i + 1] != '\n'));
  }

  // Skips blanks, line ends and "//" comments (to the end of their line, as cantools does);
  // returns false at the end of the text.
  bool skip_space() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (ends_line(pos_)) {
        ++line_;
        line_start_ = pos_ + 1;
        at_line_start_ = true;
      } else if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/') {
        while (pos_ + 1 < text_.size() && !ends_line(pos_ + 1)) ++pos_;
      } else if (c != ' ' && c != '\t' && c != '\r' && c != '\f' && c != '\v') {
        return true;
      }
      ++pos_;
    }
    return false;
  }

  Token next() {
    Token t;
    t.line = line_;
    t.column = pos_ - line_start_ + 1;
    t.opens_line = at_line_start_;
    at_line_start_ = false;
    const char c = text_[pos_];
    if (c == '"') {
      t.kind = TokenKind::String;
      t.text = read_string();
    } else if (is_ident_start(c)) {
      t.kind = TokenKind::Identifier;
      t.text = read_while(is_ident_char);
    } else if (starts_number()) {
      t.kind = TokenKind::Number;
      t.text = read_number();
      // Real files have names that start with digits ("2017_5", "64_BIT_LE").
      if (pos_ < text_.size() && is_ident_char(text_[pos_]) && is_digit(c)) {
        t.kind = TokenKind::Identifier;
        t.text += read_while(is_ident_char);
      }
    } else {
      t.kind = TokenKind::Punct;
      t.text = std::string(1, c);
      ++pos_;
    }
    return t;
  }

  // A sign starts a number only when a digit follows, so "@0-" and "@1+" stay punctuation.
  bool starts_number() const {
    const char c = text_[pos_];
    if (is_digit(c)) return true;
    if (c != '-' && c != '+' && c != '.') return false;
    std::size_t i = pos_ + 1;
    if (c != '.' && i < text_.size() && text_[i] == '.') ++i;
    return i < text_.size() && is_digit(text_[i]);
  }

  std::string read_number() {
    const std::size_t begin = pos_;
    if (text_[pos_] == '-' || text_[pos_] == '+') ++pos_;
    while (pos_ < text_.size() && (is_digit(text_[pos_]) || text_[pos_] == '.')) ++pos_;
    if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      std::size_t i = pos_ + 1;
      if (i < text_.size() && (text_[i] == '+' || text_[i] == '-')) ++i;
      if (i < text_.size() && is_digit(text_[i])) {
        pos_ = i;
        while (pos_ < text_.size() && is_digit(text_[pos_])) ++pos_;
      }
    }
    return std::string(text_.substr(begin, pos_ - begin));
  }

  template <class Pred>
  std::string read_while(Pred pred) {
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && pred(text_[pos_])) ++pos_;
    return std::string(text_.substr(begin, pos_ - begin));
  }

  // Strings may span lines (a line end is kept as '\n'); \" and \\ are escapes, any other
  // backslash is kept as written. "//" in a string is text, not a comment.
  std::string read_string() {
    const std::size_t open_line = line_;
    std::string out;
    ++pos_;
    while (pos_ < text_.size()) {
      const char c = text_[pos_++];
      if (c == '"') return out;
      if (c == '\\' && pos_ < text_.size() && (text_[pos_] == '"' || text_[pos_] == '\\')) {
        out.push_back(text_[pos_++]);
        continue;
      }
      if (ends_line(pos_ - 1)) {  // kept as '\n', whichever line end the file uses
        ++line_;
        line_start_ = pos_;
        out.push_back('\n');
      } else if (c != '\r') {
        out.push_back(c);
      }
    }
    throw InputError(std::string(name_) + ":" + std::to_string(open_line) +
                     ": unterminated string (opening quote has no closing quote)");
  }

  std::string_view text_;
  std::string_view name_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  std::size_t line_start_ = 0;
  bool at_line_start_ = true;
};

}  // namespace

std::vector<Token> tokenize_dbc(std::string_view text, std::string_view name) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
  return Lexer(text, name).run();
}

std::string describe(const Token& token) {
  switch (token.kind) {
    case TokenKind::End:
      return "end of file";
    case TokenKind::String:
      return "string \"" + token.text.substr(0, 40) + "\"";
    default:
      return "'" + token.text + "'";
  }
}

}  // namespace dynid::can::detail
