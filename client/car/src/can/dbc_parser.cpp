// DBC parser: tokens -> Database. Layout checks and derived fields are in dbc_finalize.cpp.
#include <charconv>
#include <cmath>
#include <dynid/can/dbc.hpp>
#include <dynid/error.hpp>
#include <dynid/input/ids.hpp>
#include <dynid/input/input_file.hpp>
#include <unordered_set>

#include "dbc_finalize.hpp"
#include "dbc_lexer.hpp"

namespace dynid::can {
namespace {

using detail::Token;
using detail::TokenKind;

// Every section keyword of the format; skipping an unknown section stops at the next one.
const std::unordered_set<std::string_view> kKeywords = {
    "VERSION",     "NS_",          "NS_DESC_",        "BS_",          "BU_",
    "BO_",         "SG_",          "CM_",             "BA_DEF_",      "BA_DEF_DEF_",
    "BA_",         "VAL_",         "VAL_TABLE_",      "SIG_VALTYPE_", "SG_MUL_VAL_",
    "BO_TX_BU_",   "EV_",          "SIG_GROUP_",      "BA_DEF_REL_",  "BA_REL_",
    "BA_DEF_DEF_REL_", "BU_SG_REL_", "BU_EV_REL_",    "BU_BO_REL_",   "SGTYPE_",
    "SGTYPE_VAL_", "SIG_TYPE_REF_", "SIGTYPE_VALTYPE_", "CAT_DEF_",   "CAT_",
    "FILTER",      "EV_DATA_",     "ENVVAR_DATA_",    "BA_DEF_SGTYPE_", "BA_SGTYPE_"};

class Parser {
 public:
  Parser(std::string_view text, std::string_view name)
      : name_(name), tokens_(detail::tokenize_dbc(text, name)) {
    db_.source = std::string(name);
  }

  Database run() {
    while (peek().kind != TokenKind::End) statement();
    detail::finalize_database(db_, peek().line);
    return std::move(db_);
  }

 private:
  // ---- token access -------------------------------------------------------------------
  const Token& peek() const { return tokens_[pos_]; }
  const Token& take() { return tokens_[pos_ < tokens_.size() - 1 ? pos_++ : pos_]; }
  bool at_punct(char c) const { return peek().kind == TokenKind::Punct && peek().text[0] == c; }
  bool at_ident(std::string_view word) const {
    return peek().kind == TokenKind::Identifier && peek().text == word;
  }
  // True when the current statement has ended: the next token opens a line.
  bool at_line_end() const { return peek().opens_line; }

  // "<name>:<line>: <context>: <reason>", escaped: the file's bytes (names, tokens) reach it.
  std::string located(const Token& at, std::string_view reason) const {
    return name_ + ":" + std::to_string(at.line) + ": " +
           input::printable_text(context_ + ": " + std::string(reason));
  }
  [[noreturn]] void fail(const Token& at, std::string_view reason) const {
    throw InputError(located(at, reason));
  }
  [[noreturn]] void fail_expected(std::string_view what) const {
    fail(peek(), "expected " + std::string(what) + ", found " + detail::describe(peek()));
  }

  void expect_punct(char c, std::string_view after) {
    if (!at_punct(c)) fail_expected("'" + std::string(1, c) + "' " + std::string(after));
    take();
  }
  // Some real files drop the ';' before the next section or the end of the file: accepted
  // with a warning; anything else in its place is an error.
  void expect_semicolon() {
    const bool next_section = peek().kind == TokenKind::End ||
                              (peek().opens_line && peek().kind == TokenKind::Identifier &&
                               kKeywords.count(peek().text) != 0);
    if (!at_punct(';') && next_section) return warn(peek(), "missing ';' before " +
                                                                detail::describe(peek()));
    expect_punct(';', "at the end of the statement");
  }
  std::string expect_ident(std::string_view what) {
    if (peek().kind != TokenKind::Identifier) fail_expected(what);
    return take().text;
  }
  std::string expect_string(std::string_view what) {
    if (peek().kind != TokenKind::String) fail_expected(what);
    return take().text;
  }
  double expect_double(std::string_view what) {
    if (peek().kind != TokenKind::Number) fail_expected(what);
    const Token& t = take();
    double v = 0.0;
    const auto [end, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
    if (ec != std::errc() || end != t.text.data() + t.text.size() || !std::isfinite(v))
      fail(t, "bad number '" + t.text + "' for " + std::string(what));
    return v;
  }
  std::int64_t expect_int(std::string_view what) {
    const Token& t = peek();
    const double v = expect_double(what);
    std::int64_t i = 0;
    const char* first = t.text.data() + (t.text[0] == '+' ? 1 : 0);
    const auto [end, ec] = std::from_chars(first, t.text.data() + t.text.size(), i);
    if (ec == std::errc() && end == t.text.data() + t.text.size()) return i;
    // Written as "1e+09" or "3.0": accept when it is an integer within range.
    if (v != std::floor(v) || std::fabs(v) > 9.2e18) fail(t, "expected an integer for " +
                                                               std::string(what) + ", found '" +
                                                               t.text + "'");
    return static_cast<std::int64_t>(v);
  }
  std::uint64_t expect_uint(std::string_view what) {
    const Token& t = peek();
    if (t.kind != TokenKind::Number) fail_expected(what);
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
    if (ec != std::errc() || end != t.text.data() + t.text.size())
      fail(t, "expected an unsigned integer for " + std::string(what) + ", found '" + t.text +
                  "'");
    take();
    return v;
  }
  std::uint32_t expect_u32(std::string_view what) {
    const Token& t = peek();
    const std::uint64_t v = expect_uint(what);
    if (v > 0xFFFFFFFFULL) fail(t, std::string(what) + " " + t.text + " is out of range");
    return static_cast<std::uint32_t>(v);
  }

  // ---- statements -----------------------------------------------------------------------
  void statement() {
    const Token& t = peek();
    context_ = t.text;
    if (t.kind != TokenKind::Identifier)
      fail(t, "expected a section keyword, found " + detail::describe(t));
    const std::string& k = t.text;
    const bool in_message = in_message_;  // the previous statement was a BO_ or one of its SG_
    in_message_ = k == "BO_" || k == "SG_";
    if (k == "VERSION") return version();
    if (k == "NS_") return new_symbols();
    if (k == "BS_" || k == "BU_") return node_list(k == "BU_");
    if (k == "BO_") return message();
    if (k == "SG_") return signal();
    if (k == "CM_") return comment();
    if (k == "BA_DEF_") return attribute_definition();
    if (k == "BA_DEF_DEF_") return attribute_default();
    if (k == "BA_") return attribute();
    if (k == "VAL_TABLE_") return value_table();
    if (k == "VAL_") return value_descriptions();
    if (k == "SIG_VALTYPE_") return signal_value_type();
    if (k == "SG_MUL_VAL_") return multiplex_ranges();
    if (k == "BO_TX_BU_") return transmitters();
    if (k == "EV_") return environment_variable();
    if (k == "SIG_GROUP_") return signal_group();
    if (kKeywords.count(k) != 0) return skip_section();  // a section this parser does not use
    // An unknown word: skipped with what follows, up to the next section keyword. Among the
    // signals of a message a signal may be lost there, so that message is unusable.
    const Token& at = t;
    const std::size_t first_line = at.line;
    skip_section();
    const std::string span =
        peek().line - 1 > first_line
            ? "lines " + std::to_string(first_line) + "-" + std::to_string(peek().line - 1)
            : "line " + std::to_string(first_line);
    unknown_word_ =
        "line " + std::to_string(first_line) + " starts with the unknown word '" + at.text + "'";
    if (!in_message) return warn(at, "unknown section keyword: " + span + " skipped");
    Message& m = db_.messages.back();
    in_message_ = true;  // its SG_ lines may follow
    if (m.usable())
      m.problem = located(at, "unknown section keyword among the signals of message '" + m.name +
                                  "' (" + span + " skipped): a signal may be missing");
  }

  // Skips to the next line that starts with a section keyword.
  void skip_section() {
    take();
    while (peek().kind != TokenKind::End &&
           !(peek().opens_line && peek().kind == TokenKind::Identifier &&
             kKeywords.count(peek().text) != 0))
      take();
  }

  void version() {
    take();
    db_.version = expect_string("a version string after VERSION");
  }

  // NS_ lists the optional symbols, one per indented line, until a line starts at column 1
  // or with BS_, BU_ or BO_ (never optional symbols; some files indent them).
  void new_symbols() {
    take();
    if (at_punct(':')) take();
    while (peek().kind != TokenKind::End && !(peek().opens_line && peek().column == 1) &&
           !(peek().opens_line && (at_ident("BS_") || at_ident("BU_") || at_ident("BO_"))))
      db_.new_symbols.push_back(take().text);
  }

  // "BS_: [baud : btr1, btr2]" (ignored) and "BU_: node node ...". The nodes may go on over
  // indented lines (one per line in Tesla's files).
  void node_list(bool nodes) {
    take();
    expect_punct(':', "after " + context_);
    while (!at_line_end() || (nodes && peek().kind == TokenKind::Identifier && peek().column > 1 &&
                              kKeywords.count(peek().text) == 0)) {
      const Token& t = take();
      if (nodes && t.kind == TokenKind::Identifier) db_.nodes.push_back(Node{t.text, {}, {}});
      else if (nodes) fail(t, "expected a node name, found " + detail::describe(t));
    }
  }

  // Problems of the message alone (size, an id another message has) make it unusable.
  void message() {
    take();
    const Token& id_token = peek();
    const std::uint32_t raw_id = expect_u32("a message id");
    Message m;
    m.line = id_token.line;
    m.name = expect_ident("a message name");
    context_ = "BO_ '" + m.name + "'";
    if (const std::string why = detail::set_message_id(m, raw_id); !why.empty())
      warn(id_token, why);
    const std::uint32_t key = detail::message_key(raw_id);
    if (const auto [it, fresh] = db_.message_by_key.emplace(key, db_.messages.size()); !fresh) {
      Message& first = db_.messages[it->second];  // references keep going to the first
      m.problem = located(id_token, "id " + id_token.text + " is already used by message '" +
                                        first.name + "' (line " + std::to_string(first.line) + ")");
      if (first.usable())
        first.problem = name_ + ":" + std::to_string(first.line) + ": " +
                        input::printable_text("BO_ '" + first.name + "': id " + id_token.text +
                                              " is also used by message '" + m.name + "' (line " +
                                              std::to_string(m.line) + ")");
    }
    expect_punct(':', "after the message name");
    const Token& size_token = peek();
    m.size = expect_u32("the message size");
    if (m.size > 64 && m.usable())
      m.problem = located(size_token, "size " + size_token.text + " exceeds 64 bytes");
    m.transmitter = expect_ident("the transmitting node");
    if (!at_line_end()) fail_expected("the end of the line after the transmitter");
    db_.messages.push_back(std::move(m));
  }

  void signal() {
    const Token& keyword = take();
    if (db_.messages.empty())
      fail(keyword, "signal outside a message (no BO_ before it" +
                        (unknown_word_.empty() ? std::string() : "; " + unknown_word_) + ")");
    Signal s;
    s.name = expect_ident("a signal name");
    context_ = "SG_ '" + s.name + "'";
    if (peek().kind == TokenKind::Identifier) multiplex_indicator(s, take());
    expect_punct(':', "after the signal name");
    s.start_bit = expect_u32("the start bit");
    expect_punct('|', "after the start bit");
    s.length = expect_u32("the length");
    expect_punct('@', "after length");
    byte_order_and_sign(s);
    expect_punct('(', "before factor");
    s.factor = expect_double("the factor");
    expect_punct(',', "between factor and offset");
    s.offset = expect_double("the offset");
    expect_punct(')', "after offset");
    expect_punct('[', "before minimum");
    s.minimum = expect_double("the minimum");
    expect_punct('|', "between minimum and maximum");
    s.maximum = expect_double("the maximum");
    expect_punct(']', "after maximum");
    s.unit = expect_string("the unit string");
    s.receivers = name_list();
    s.line = keyword.line;
    db_.messages.back().signals.push_back(std::move(s));
  }

  // "M" (switch), "m3" (selected by value 3), "m3M" (both: extended multiplexing).
  void multiplex_indicator(Signal& s, const Token& t) {
    std::string_view v = t.text;
    if (v == "M") {
      s.is_multiplexer = true;
      return;
    }
    if (v.size() < 2 || v[0] != 'm') fail(t, "bad multiplexer indicator '" + t.text + "'");
    v.remove_prefix(1);
    if (v.back() == 'M') {
      s.is_multiplexer = true;
      v.remove_suffix(1);
    }
    std::uint64_t value = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
    if (ec != std::errc() || end != v.data() + v.size())
      fail(t, "bad multiplexer indicator '" + t.text + "'");
    s.mux_value = value;
  }

  // "@1+" / "@0-": the digit is a number token, the sign a punctuation token.
  void byte_order_and_sign(Signal& s) {
    const Token& t = peek();
    if (t.kind != TokenKind::Number || (t.text != "0" && t.text != "1"))
      fail_expected("byte order 0 (Motorola) or 1 (Intel) after '@'");
    s.byte_order = t.text == "1" ? ByteOrder::Intel : ByteOrder::Motorola;
    take();
    if (!at_punct('+') && !at_punct('-')) fail_expected("'+' or '-' after the byte order");
    s.is_signed = take().text == "-";
  }

  // Comma-separated names up to the end of the line (receivers, transmitters).
  std::vector<std::string> name_list() {
    std::vector<std::string> names;
    while (!at_line_end() && !at_punct(';')) {
      if (at_punct(',')) {
        take();
        continue;
      }
      names.push_back(expect_ident("a node name"));
    }
    return names;
  }

  // ---- object references (CM_, BA_, VAL_, ...) ------------------------------------------
  Message* message_ref(const Token& at, std::uint32_t raw_id) {
    const auto it = db_.message_by_key.find(detail::message_key(raw_id));
    if (it != db_.message_by_key.end()) return &db_.messages[it->second];
    warn(at, "message id " + std::to_string(raw_id) + " is not defined by a BO_");
    return nullptr;
  }
  // Every signal of `m` called `name`: a repeated name is ambiguous, and a reference to it
  // applies to each copy (as in cantools, which keys them by name).
  std::vector<Signal*> signal_refs(const Token& at, Message* m, const std::string& name) {
    std::vector<Signal*> out;
    if (m == nullptr) return out;
    for (Signal& s : m->signals)
      if (s.name == name) out.push_back(&s);
    if (out.empty()) warn(at, "message '" + m->name + "' has no signal '" + name + "'");
    return out;
  }
  Node* node_ref(const Token& at, const std::string& name) {
    for (Node& n : db_.nodes)
      if (n.name == name) return &n;
    warn(at, "node '" + name + "' is not listed in BU_");
    return nullptr;
  }
  EnvironmentVariable* env_ref(const Token& at, const std::string& name) {
    for (EnvironmentVariable& e : db_.environment_variables)
      if (e.name == name) return &e;
    warn(at, "environment variable '" + name + "' is not defined by an EV_");
    return nullptr;
  }
  void warn(const Token& at, const std::string& what) {
    db_.warnings.push_back(name_ + ":" + std::to_string(at.line) + ": " + input::printable_text(context_ + ": " + what));
  }

  // Where a CM_ or BA_ applies: the network, a node, a message, a signal or a variable.
  struct Target {
    AttributeScope scope = AttributeScope::Network;
    Node* node = nullptr;
    Message* message = nullptr;
    std::vector<Signal*> signals;
    EnvironmentVariable* env = nullptr;
    bool dangling = false;
  };
  // `bare_id`: CM_ accepts a bare message id; in BA_ a bare number is the network's value.
  Target target(bool bare_id) {
    Target t;
    const Token& at = peek();
    if (at_ident("BU_")) {
      take();
      t.scope = AttributeScope::Node;
      t.node = node_ref(at, expect_ident("a node name"));
      t.dangling = t.node == nullptr;
    } else if (at_ident("BO_") || at_ident("SG_") ||
               (bare_id && peek().kind == TokenKind::Number)) {
      // A bare id ("CM_ 272 "...";", seen in opendbc) is taken as a message.
      const bool bare = peek().kind == TokenKind::Number;
      const bool sig = !bare && take().text == "SG_";
      if (bare) warn(at, "object type missing before the id: taken as BO_");
      t.scope = sig ? AttributeScope::Signal : AttributeScope::Message;
      t.message = message_ref(at, expect_u32("a message id"));
      if (sig && peek().kind == TokenKind::String) {
        warn(at, "SG_ without a signal name: ignored");
        t.dangling = true;
        return t;
      }
      if (sig) t.signals = signal_refs(at, t.message, expect_ident("a signal name"));
      t.dangling = sig ? t.signals.empty() : t.message == nullptr;
    } else if (at_ident("EV_")) {
      take();
      t.scope = AttributeScope::EnvVar;
      t.env = env_ref(at, expect_ident("a variable name"));
      t.dangling = t.env == nullptr;
    }
    return t;
  }

  void comment() {
    take();
    Target t = target(true);
    std::string text = expect_string("the comment string");
    expect_semicolon();
    if (t.dangling) return;
    switch (t.scope) {
      case AttributeScope::Network: db_.comment = std::move(text); break;
      case AttributeScope::Node: t.node->comment = std::move(text); break;
      case AttributeScope::Message: t.message->comment = std::move(text); break;
      case AttributeScope::Signal:
        for (Signal* s : t.signals) s->comment = text;
        break;
      case AttributeScope::EnvVar: t.env->comment = std::move(text); break;
    }
  }

  // ---- attributes -----------------------------------------------------------------------
  void attribute_definition() {
    take();
    AttributeDefinition d;
    d.scope = definition_scope();
    d.name = expect_string("the attribute name");
    context_ = "BA_DEF_ '" + d.name + "'";
    const Token& type = peek();
    const std::string kind = expect_ident("an attribute type (INT, HEX, FLOAT, STRING, ENUM)");
    if (kind == "INT" || kind == "HEX" || kind == "FLOAT") {
      d.type = kind == "INT" ? AttributeType::Int
                             : (kind == "HEX" ? AttributeType::Hex : AttributeType::Float);
      d.minimum = expect_double("the minimum");
      d.maximum = expect_double("the maximum");
    } else if (kind == "STRING") {
      d.type = AttributeType::String;
    } else if (kind == "ENUM") {
      d.type = AttributeType::Enum;
      d.enum_values = enum_values();
    } else {
      fail(type, "unknown attribute type '" + kind + "'");
    }
    expect_semicolon();
    db_.attribute_definitions[d.name] = std::move(d);
  }

  AttributeScope definition_scope() {
    if (at_ident("BU_")) return take(), AttributeScope::Node;
    if (at_ident("BO_")) return take(), AttributeScope::Message;
    if (at_ident("SG_")) return take(), AttributeScope::Signal;
    if (at_ident("EV_")) return take(), AttributeScope::EnvVar;
    return AttributeScope::Network;
  }

  std::vector<std::string> enum_values() {
    std::vector<std::string> values;
    while (peek().kind == TokenKind::String) {
      values.push_back(take().text);
      if (!at_punct(',')) break;
      take();
    }
    return values;
  }

  // A value typed by its definition when there is one, else by how it is written.
  AttributeValue attribute_literal(std::string_view name) {
    const auto def = db_.attribute_definitions.find(name);
    if (peek().kind == TokenKind::String) return take().text;
    if (peek().kind != TokenKind::Number) fail_expected("an attribute value");
    const bool real_def = def != db_.attribute_definitions.end() &&
                          def->second.type == AttributeType::Float;
    const std::string& text = peek().text;
    const bool looks_real = text.find_first_of(".eE") != std::string::npos;
    if (real_def || (def == db_.attribute_definitions.end() && looks_real))
      return expect_double("the attribute value");
    return expect_int("the attribute value");
  }

  void attribute_default() {
    take();
    const std::string name = expect_string("the attribute name");
    context_ = "BA_DEF_DEF_ '" + name + "'";
    AttributeValue v = attribute_literal(name);
    expect_semicolon();
    const auto def = db_.attribute_definitions.find(name);
    if (def == db_.attribute_definitions.end())
      return warn(tokens_[pos_ - 1], "no BA_DEF_ defines '" + name + "'");
    def->second.default_value = std::move(v);
  }

  void attribute() {
    take();
    const std::string name = expect_string("the attribute name");
    context_ = "BA_ '" + name + "'";
    Target t = target(false);
    AttributeValue v = attribute_literal(name);
    expect_semicolon();
    if (t.dangling) return;
    switch (t.scope) {
      case AttributeScope::Network: db_.network_attributes[name] = std::move(v); break;
      case AttributeScope::Node: t.node->attributes[name] = std::move(v); break;
      case AttributeScope::Message: t.message->attributes[name] = std::move(v); break;
      case AttributeScope::Signal:
        for (Signal* s : t.signals) s->attributes[name] = v;
        break;
      case AttributeScope::EnvVar: t.env->attributes[name] = std::move(v); break;
    }
  }

  // ---- value descriptions ---------------------------------------------------------------
  std::map<std::int64_t, std::string> value_pairs() {
    std::map<std::int64_t, std::string> out;
    while (peek().kind == TokenKind::Number) {
      const std::int64_t key = expect_int("a value");
      out[key] = expect_string("the description of the value");
    }
    expect_semicolon();
    return out;
  }

  void value_table() {
    take();
    const std::string name = expect_ident("a value table name");
    context_ = "VAL_TABLE_ '" + name + "'";
    db_.value_tables[name] = value_pairs();
  }

  // "VAL_ <id> <signal> pairs ;" or "VAL_ <variable> pairs ;".
  void value_descriptions() {
    const Token& at = take();
    if (peek().kind == TokenKind::Identifier) {
      const std::string env = take().text;
      context_ = "VAL_ '" + env + "'";
      auto pairs = value_pairs();
      if (EnvironmentVariable* e = env_ref(at, env)) e->value_descriptions = std::move(pairs);
      return;
    }
    const std::uint32_t id = expect_u32("a message id");
    const std::string sig = expect_ident("a signal name");
    context_ = "VAL_ '" + sig + "'";
    Message* m = message_ref(at, id);
    const auto pairs = value_pairs();
    for (Signal* s : signal_refs(at, m, sig)) s->value_descriptions = pairs;
  }

  // ---- signal extras --------------------------------------------------------------------
  void signal_value_type() {
    const Token& at = take();
    const std::uint32_t id = expect_u32("a message id");
    const std::string sig = expect_ident("a signal name");
    context_ = "SIG_VALTYPE_ '" + sig + "'";
    Message* m = message_ref(at, id);
    if (at_punct(':')) take();
    const Token& vt = peek();
    const std::uint64_t code = expect_uint("the value type (0, 1 or 2)");
    if (code > 2) fail(vt, "value type " + vt.text + " is not 0 (integer), 1 (float) or 2 (double)");
    expect_semicolon();
    for (Signal* s : signal_refs(at, m, sig)) s->value_type = static_cast<ValueType>(code);
  }

  // "SG_MUL_VAL_ <id> <signal> <switch> 3-3, 5-10 ;". The lexer reads "3-3" as 3 and -3.
  void multiplex_ranges() {
    const Token& at = take();
    const std::uint32_t id = expect_u32("a message id");
    const std::string sig = expect_ident("a signal name");
    context_ = "SG_MUL_VAL_ '" + sig + "'";
    Message* m = message_ref(at, id);
    const std::string sw = expect_ident("the multiplexer switch name");
    std::vector<MuxRange> ranges;
    while (peek().kind == TokenKind::Number) {
      MuxRange r;
      r.low = expect_uint("the low end of a range");
      if (at_punct('-')) take();
      const Token& high = peek();
      if (high.kind != TokenKind::Number) fail_expected("the high end of a range");
      const std::string digits = high.text[0] == '-' ? high.text.substr(1) : high.text;
      const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), r.high);
      if (ec != std::errc() || end != digits.data() + digits.size() || r.high < r.low)
        fail(high, "bad range end '" + high.text + "'");
      take();
      ranges.push_back(r);
      if (at_punct(',')) take();
    }
    expect_semicolon();
    for (Signal* s : signal_refs(at, m, sig)) {
      s->multiplexer = sw;
      s->mux_ranges.insert(s->mux_ranges.end(), ranges.begin(), ranges.end());
    }
  }

  void transmitters() {
    const Token& at = take();
    Message* m = message_ref(at, expect_u32("a message id"));
    expect_punct(':', "after the message id");
    std::vector<std::string> names = name_list();
    expect_semicolon();
    if (m != nullptr) m->extra_transmitters = std::move(names);
  }

  void signal_group() {
    const Token& at = take();
    Message* m = message_ref(at, expect_u32("a message id"));
    SignalGroup g;
    g.name = expect_ident("a signal group name");
    context_ = "SIG_GROUP_ '" + g.name + "'";
    g.repetitions = expect_u32("the repetitions");
    expect_punct(':', "after the repetitions");
    while (peek().kind == TokenKind::Identifier) g.signals.push_back(take().text);
    expect_semicolon();
    if (m != nullptr) m->signal_groups.push_back(std::move(g));
  }

  // "EV_ name : type [min|max] "unit" initial id access_type node, node ;"
  void environment_variable() {
    take();
    EnvironmentVariable e;
    e.name = expect_ident("a variable name");
    context_ = "EV_ '" + e.name + "'";
    expect_punct(':', "after the variable name");
    e.type = static_cast<int>(expect_int("the variable type"));
    expect_punct('[', "before minimum");
    e.minimum = expect_double("the minimum");
    expect_punct('|', "between minimum and maximum");
    e.maximum = expect_double("the maximum");
    expect_punct(']', "after maximum");
    e.unit = expect_string("the unit string");
    e.initial_value = expect_double("the initial value");
    e.ev_id = expect_int("the variable id");
    e.access_type = expect_ident("the access type");
    e.access_nodes = name_list();
    expect_semicolon();
    db_.environment_variables.push_back(std::move(e));
  }

  std::string name_;
  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  std::string context_;
  bool in_message_ = false;
  std::string unknown_word_;  // the last one skipped, for the error of a lost BO_
  Database db_;
};

}  // namespace

Database parse_dbc_string(std::string_view text, std::string_view name) {
  return Parser(text, name).run();
}

Database parse_dbc_file(const std::filesystem::path& path) {
  return parse_dbc_string(input::read_input_file(path, "DBC file"), path.filename().string());
}

}  // namespace dynid::can
