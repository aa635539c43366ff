#pragma once
// Tokens of a DBC file (private to the parser).
//
// DBC is a free-form token language whose statements mostly start at the beginning of a line;
// the lexer keeps each token's line and whether it opens its line, which the parser uses to
// end statements that have no terminator (BO_, SG_, BU_) and to skip unknown sections. Lines
// end with LF, CRLF or a lone CR; "//" outside a string starts a comment up to the line's end.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::can::detail {

enum class TokenKind { Identifier, Number, String, Punct, End };

struct Token {
  TokenKind kind = TokenKind::End;
  std::string text;  // strings: unescaped content without the quotes
  std::size_t line = 0;
  std::size_t column = 0;  // 1-based
  bool opens_line = false;
};

// Splits `text` into tokens. Throws InputError "<name>:<line>: <reason>" on an unterminated
// string or a character that cannot start a token.
std::vector<Token> tokenize_dbc(std::string_view text, std::string_view name);

// What a token looks like in an error message.
std::string describe(const Token& token);

}  // namespace dynid::can::detail
