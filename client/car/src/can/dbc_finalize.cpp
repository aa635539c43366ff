#include "dbc_finalize.hpp"

#include <algorithm>
#include <dynid/can/frame.hpp>
#include <dynid/error.hpp>

namespace dynid::can::detail {
namespace {

constexpr std::uint32_t kPseudoMessageId = 0xC0000000U;
constexpr std::uint32_t kMaxBits = 64 * 8;

class MessageChecker {
 public:
  MessageChecker(Database& db, Message& m, std::size_t line,
                 const std::vector<std::size_t>& signal_lines)
      : db_(db), m_(m), line_(line), signal_lines_(signal_lines) {}

  void run() {
    index_signals();
    for (std::size_t i = 0; i < m_.signals.size(); ++i) check_layout(i);
    if (m_.required_bytes > m_.size && !m_.is_pseudo)
      db_.warnings.push_back(where(line_) + "BO_ '" + m_.name + "': signals need " +
                             std::to_string(m_.required_bytes) + " bytes but the size is " +
                             std::to_string(m_.size));
    for (std::size_t i = 0; i < m_.signals.size(); ++i) link_multiplexer(i);
    order_for_decoding();
    const auto format = attribute_value(db_, m_.attributes, "VFrameFormat");
    const auto* name = format ? std::get_if<std::string>(&*format) : nullptr;
    m_.fd = m_.size > Frame::kMaxClassicData ||
            (name != nullptr && name->find("FD") != std::string::npos);
  }

 private:
  std::string where(std::size_t line) const {
    return db_.source + ":" + std::to_string(line) + ": ";
  }
  [[noreturn]] void fail(std::size_t i, const std::string& reason) const {
    throw InputError(where(signal_lines_[i]) + "SG_ '" + m_.signals[i].name + "': " + reason);
  }

  void index_signals() {
    m_.signal_by_name.clear();
    for (std::size_t i = 0; i < m_.signals.size(); ++i)
      if (!m_.signal_by_name.emplace(m_.signals[i].name, i).second)
        fail(i, "duplicate signal name in message '" + m_.name + "'");
  }

  void check_layout(std::size_t i) {
    const Signal& s = m_.signals[i];
    if (s.length < 1 || s.length > 64) fail(i, "length " + std::to_string(s.length) +
                                                   " is outside 1..64 bits");
    if (s.value_type == ValueType::Float32 && s.length != 32)
      fail(i, "a float signal (SIG_VALTYPE_ 1) must be 32 bits long, not " +
                  std::to_string(s.length));
    if (s.value_type == ValueType::Float64 && s.length != 64)
      fail(i, "a double signal (SIG_VALTYPE_ 2) must be 64 bits long, not " +
                  std::to_string(s.length));
    if (s.start_bit >= kMaxBits) fail(i, "start bit " + std::to_string(s.start_bit) +
                                             " is beyond 64 bytes");
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
      if (!s.multiplexer.empty()) fail(i, "SG_MUL_VAL_ names a switch but the signal has no "
                                          "multiplexer indicator (m<value>)");
      return;
    }
    if (s.multiplexer.empty()) s.multiplexer = plain_switch(i);
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
    if (found.empty()) fail(i, "multiplexed (m" + std::to_string(*m_.signals[i].mux_value) +
                                   ") but message '" + m_.name + "' has no switch signal (M)");
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

  Database& db_;
  Message& m_;
  std::size_t line_;
  const std::vector<std::size_t>& signal_lines_;
  std::vector<int> state_;
};

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
    return "id " + std::to_string(raw_id) + " has more than 29 bits: kept as a pseudo message "
           "that no frame can address";
  }
  if (key != raw_id)
    return "id " + std::to_string(raw_id) + " exceeds 11 bits without the extended flag "
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

void finalize_database(Database& db, const SourceLines& lines) {
  for (std::size_t i = 0; i < db.messages.size(); ++i)
    MessageChecker(db, db.messages[i], lines.messages[i], lines.signals[i]).run();
}

}  // namespace dynid::can::detail
