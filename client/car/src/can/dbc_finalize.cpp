#include "dbc_finalize.hpp"

#include <algorithm>
#include <dynid/can/frame.hpp>
#include <dynid/error.hpp>
#include <unordered_map>

namespace dynid::can::detail {
namespace {

constexpr std::uint32_t kPseudoMessageId = 0xC0000000U;
constexpr std::uint32_t kMaxBits = 64 * 8;

std::string where(const Database& db, std::size_t line) {
  return db.source + ":" + std::to_string(line) + ": ";
}

// Checks one message and fills its derived fields; throws InputError naming file:line for a
// problem, and adds its warnings to the database only when it passes.
class MessageChecker {
 public:
  MessageChecker(Database& db, Message& m) : db_(db), m_(m) {}

  void run() {
    index_signals();
    for (std::size_t i = 0; i < m_.signals.size(); ++i) check_layout(i);
    if (m_.required_bytes > m_.size && !m_.is_pseudo)
      warnings_.push_back(where(db_, m_.line) + "BO_ '" + m_.name + "': signals need " +
                          std::to_string(m_.required_bytes) + " bytes but the size is " +
                          std::to_string(m_.size));
    for (std::size_t i = 0; i < m_.signals.size(); ++i) link_multiplexer(i);
    check_repeated_names();
    order_for_decoding();
    for (const std::size_t i : m_.decode_order) check_presence(i);  // switches first
    const auto format = attribute_value(db_, m_.attributes, "VFrameFormat");
    const auto* name = format ? std::get_if<std::string>(&*format) : nullptr;
    m_.fd = m_.size > Frame::kMaxClassicData ||
            (name != nullptr && name->find("FD") != std::string::npos);
    db_.warnings.insert(db_.warnings.end(), warnings_.begin(), warnings_.end());
  }

 private:
  [[noreturn]] void fail(std::size_t i, const std::string& reason) const {
    throw InputError(where(db_, m_.signals[i].line) + "SG_ '" + m_.signals[i].name +
                     "': " + reason);
  }

  // A name carried once goes to signal_by_name; repeated names wait for check_repeated_names.
  void index_signals() {
    m_.signal_by_name.clear();
    m_.ambiguous_signals.clear();
    repeated_.clear();
    std::unordered_map<std::string_view, std::vector<std::size_t>> by_name;
    for (std::size_t i = 0; i < m_.signals.size(); ++i) by_name[m_.signals[i].name].push_back(i);
    for (auto& [name, copies] : by_name) {
      if (copies.size() == 1)
        m_.signal_by_name.emplace(std::string(name), copies[0]);
      else
        repeated_.push_back(std::move(copies));
    }
    std::sort(repeated_.begin(), repeated_.end());  // file order, for the warnings
  }
  bool is_repeated(std::string_view name) const {
    for (const auto& copies : repeated_)
      if (m_.signals[copies[0]].name == name) return true;
    return false;
  }

  // A name repeated under values of one switch that never select two of its signals together
  // (radar messages repeat CHECKSUM in each group) is ambiguous: each copy decodes, no profile
  // selects the name. Repeated where two copies can be in one frame, the message is unusable.
  void check_repeated_names() {
    for (const auto& copies : repeated_) {
      for (std::size_t a = 1; a < copies.size(); ++a)
        for (std::size_t b = 0; b < a; ++b)
          if (!exclusive(m_.signals[copies[b]], m_.signals[copies[a]]))
            fail(copies[a], "duplicate signal name in message '" + m_.name + "': line " +
                                std::to_string(m_.signals[copies[b]].line) +
                                " has it too, and both can be in one frame");
      const std::string& name = m_.signals[copies[0]].name;
      std::vector<std::size_t>& lines = m_.ambiguous_signals[name];
      std::string list;
      for (const std::size_t i : copies) {
        lines.push_back(m_.signals[i].line);
        list += (list.empty() ? "" : ", ") + std::to_string(m_.signals[i].line);
      }
      warnings_.push_back(where(db_, lines[0]) + "SG_ '" + name +
                          "': " + std::to_string(copies.size()) + " signals of message '" +
                          m_.name + "' have this name (lines " + list +
                          ") under different multiplexer values: each decodes, but a profile "
                          "cannot select the name");
    }
  }
  static bool exclusive(const Signal& x, const Signal& y) {
    if (x.multiplexer_index < 0 || x.multiplexer_index != y.multiplexer_index) return false;
    for (const MuxRange& rx : x.mux_ranges)
      for (const MuxRange& ry : y.mux_ranges)
        if (rx.low <= ry.high && ry.low <= rx.high) return false;
    return true;
  }

  void check_layout(std::size_t i) {
    const Signal& s = m_.signals[i];
    if (s.length < 1 || s.length > 64)
      fail(i, "length " + std::to_string(s.length) + " is outside 1..64 bits");
    if (s.value_type == ValueType::Float32 && s.length != 32)
      fail(i,
           "a float signal (SIG_VALTYPE_ 1) must be 32 bits long, not " + std::to_string(s.length));
    if (s.value_type == ValueType::Float64 && s.length != 64)
      fail(i, "a double signal (SIG_VALTYPE_ 2) must be 64 bits long, not " +
                  std::to_string(s.length));
    if (s.start_bit >= kMaxBits)
      fail(i, "start bit " + std::to_string(s.start_bit) + " is beyond 64 bytes");
    const ByteSpan span = signal_bytes(s);
    if (span.last >= 64 || (s.byte_order == ByteOrder::Intel && s.start_bit + s.length > kMaxBits))
      fail(i, "bits run past byte 64 (start " + std::to_string(s.start_bit) + ", length " +
                  std::to_string(s.length) + ")");
    m_.required_bytes = std::max(m_.required_bytes, span.last + 1);
  }

  // The switch of a multiplexed signal: SG_MUL_VAL_'s, else the message's only plain "M".
  void link_multiplexer(std::size_t i) {
    Signal& s = m_.signals[i];
    if (!s.is_multiplexed()) {
      if (!s.multiplexer.empty())
        fail(i,
             "SG_MUL_VAL_ names a switch but the signal has no "
             "multiplexer indicator (m<value>)");
      return;
    }
    if (s.multiplexer.empty()) s.multiplexer = plain_switch(i);
    if (is_repeated(s.multiplexer))
      fail(i, "multiplexer switch '" + s.multiplexer + "' is ambiguous: several signals of '" +
                  m_.name + "' have that name");
    const auto it = m_.signal_by_name.find(s.multiplexer);
    if (it == m_.signal_by_name.end())
      fail(i, "multiplexer switch '" + s.multiplexer + "' is not a signal of '" + m_.name + "'");
    if (!m_.signals[it->second].is_multiplexer || it->second == i)
      fail(i, "'" + s.multiplexer + "' is not a multiplexer switch (M or m<value>M)");
    s.multiplexer_index = static_cast<int>(it->second);
    if (s.mux_ranges.empty()) s.mux_ranges.push_back(MuxRange{*s.mux_value, *s.mux_value});
  }

  std::string plain_switch(std::size_t i) const {
    std::string found;
    for (const Signal& s : m_.signals) {
      if (!s.is_multiplexer || s.is_multiplexed()) continue;
      if (!found.empty())
        fail(i, "message '" + m_.name + "' has several switches ('" + found + "', '" + s.name +
                    "') and no SG_MUL_VAL_ says which one selects this signal");
      found = s.name;
    }
    if (found.empty())
      fail(i, "multiplexed (m" + std::to_string(*m_.signals[i].mux_value) + ") but message '" +
                  m_.name + "' has no switch signal (M)");
    return found;
  }

  // Depth-first: a switch is decoded before every signal it selects; cycles are errors.
  void order_for_decoding() {
    m_.decode_order.clear();
    state_.assign(m_.signals.size(), 0);
    for (std::size_t i = 0; i < m_.signals.size(); ++i) visit(i);
  }
  void visit(std::size_t i) {
    if (state_[i] == 2) return;
    if (state_[i] == 1) fail(i, "multiplexer switches form a cycle");
    state_[i] = 1;
    const int sw = m_.signals[i].multiplexer_index;
    if (sw >= 0) visit(static_cast<std::size_t>(sw));
    state_[i] = 2;
    m_.decode_order.push_back(i);
  }

  // A multiplexed signal whose switch cannot hold any of its values is in no frame: a profile
  // mapping it would get no sample, ever (every row of its channel invalid, silently).
  void check_presence(std::size_t i) {
    Signal& s = m_.signals[i];
    s.never_present.clear();
    if (s.multiplexer_index < 0) return;
    const Signal& sw = m_.signals[static_cast<std::size_t>(s.multiplexer_index)];
    std::string why;
    if (!sw.never_present.empty())
      why = "its switch '" + sw.name + "' is never present itself (line " +
            std::to_string(sw.line) + ")";
    else if (sw.value_type != ValueType::Integer)
      why = "its switch '" + sw.name +
            "' is a float signal (SIG_VALTYPE_), which selects by no value";
    else if (sw.length < 64 && !reachable(s, (std::uint64_t{1} << sw.length) - 1))
      why = "multiplexer " + mux_values(s) + " beyond what its switch '" + sw.name + "' (" +
            std::to_string(sw.length) + " bits, 0.." +
            std::to_string((std::uint64_t{1} << sw.length) - 1) + ") can hold";
    if (why.empty()) return;
    s.never_present = where(db_, s.line) + "SG_ '" + s.name + "' of message '" + m_.name +
                      "' is in no frame: " + why;
    warnings_.push_back(s.never_present);
  }
  static bool reachable(const Signal& s, std::uint64_t highest) {
    return std::any_of(s.mux_ranges.begin(), s.mux_ranges.end(),
                       [highest](const MuxRange& r) { return r.low <= highest; });
  }
  // "value 300", "values 300..310, 400".
  static std::string mux_values(const Signal& s) {
    std::string out;
    for (const MuxRange& r : s.mux_ranges)
      out += (out.empty() ? "" : ", ") + std::to_string(r.low) +
             (r.high == r.low ? "" : ".." + std::to_string(r.high));
    const bool one = s.mux_ranges.size() == 1 && s.mux_ranges[0].low == s.mux_ranges[0].high;
    return (one ? "value " : "values ") + out + (one ? " is" : " are");
  }

  Database& db_;
  Message& m_;
  std::vector<int> state_;
  std::vector<std::vector<std::size_t>> repeated_;  // indices of each repeated name's signals
  std::vector<std::string> warnings_;
};

// Two messages with one name both decode by id; the name selects neither.
void warn_shared_names(Database& db) {
  std::unordered_map<std::string_view, std::size_t> first;
  for (std::size_t i = 0; i < db.messages.size(); ++i) {
    const Message& m = db.messages[i];
    const auto [it, fresh] = first.emplace(m.name, i);
    if (fresh) continue;
    const Message& f = db.messages[it->second];
    db.warnings.push_back(where(db, m.line) + "BO_ '" + m.name +
                          "': name also used by the message at line " + std::to_string(f.line) +
                          " (id " + id_text(f) + "; this one: " + id_text(m) +
                          "): both decode by id, a profile cannot select them by name");
  }
}

}  // namespace

std::uint32_t message_key(std::uint32_t raw_id) {
  const bool plain = (raw_id & kDbcExtendedFlag) == 0;
  if (plain && raw_id > Frame::kMaxStandardId && raw_id <= Frame::kMaxExtendedId)
    return raw_id | kDbcExtendedFlag;
  return raw_id;
}

std::string set_message_id(Message& m, std::uint32_t raw_id) {
  const std::uint32_t key = message_key(raw_id);
  m.dbc_id = raw_id;
  m.extended = (key & kDbcExtendedFlag) != 0;
  m.id = key & ~kDbcExtendedFlag;
  if (m.id > Frame::kMaxExtendedId) {
    m.is_pseudo = true;
    m.id = 0;
    if (raw_id == kPseudoMessageId || raw_id == (kPseudoMessageId & ~kDbcExtendedFlag)) return {};
    return "id " + std::to_string(raw_id) +
           " has more than 29 bits: kept as a pseudo message "
           "that no frame can address";
  }
  if (key != raw_id)
    return "id " + std::to_string(raw_id) +
           " exceeds 11 bits without the extended flag "
           "(bit 31): taken as a 29-bit id";
  return {};
}

ByteSpan signal_bytes(const Signal& s) {
  const std::uint32_t first = s.start_bit / 8;
  if (s.byte_order == ByteOrder::Intel) return {first, (s.start_bit + s.length - 1) / 8};
  // Motorola: the MSB sits at start_bit; bits run down to bit 0, then on to the next byte.
  const std::uint32_t in_first = s.start_bit % 8 + 1;
  if (s.length <= in_first) return {first, first};
  return {first, first + (s.length - in_first + 7) / 8};
}

void finalize_database(Database& db, std::size_t last_line) {
  for (Message& m : db.messages) {
    if (!m.usable()) continue;  // the parser found its problem
    try {
      MessageChecker(db, m).run();
    } catch (const InputError& e) {
      m.problem = e.what();
    }
  }
  db.message_by_key.clear();
  for (std::size_t i = 0; i < db.messages.size(); ++i) {
    const Message& m = db.messages[i];
    if (m.usable()) {
      db.message_by_key.emplace(message_key(m.dbc_id), i);
      continue;
    }
    db.warnings.push_back(m.problem + "; message '" + m.name + "' (line " + std::to_string(m.line) +
                          ") is unusable: not decoded, and a profile cannot select it");
  }
  warn_shared_names(db);
  if (db.messages.empty())
    db.warnings.push_back(where(db, last_line) + "the file defines no message (BO_)");
}

}  // namespace dynid::can::detail
