// Database lookups and attribute resolution. The parser is in dbc_parser.cpp.
#include <cstdio>
#include <dynid/can/dbc.hpp>
#include <dynid/can/frame.hpp>

namespace dynid::can {

bool Signal::mux_accepts(std::uint64_t switch_raw) const {
  for (const MuxRange& r : mux_ranges)
    if (switch_raw >= r.low && switch_raw <= r.high) return true;
  return false;
}

std::optional<std::size_t> Message::signal_index(std::string_view signal_name) const {
  const auto it = signal_by_name.find(std::string(signal_name));
  if (it == signal_by_name.end()) return std::nullopt;
  return it->second;
}

const Signal* Message::find_signal(std::string_view signal_name) const {
  const auto i = signal_index(signal_name);
  return i ? &signals[*i] : nullptr;
}

const Message* Database::find_message(std::uint32_t id, bool extended) const {
  if (id > (extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId)) return nullptr;
  const auto it = message_by_key.find(dbc_key(id, extended));
  return it == message_by_key.end() ? nullptr : &messages[it->second];
}

const Message* Database::find_message(std::string_view name) const {
  const Message* found = nullptr;
  for (const Message& m : messages) {
    if (m.name != name) continue;
    if (found != nullptr) return nullptr;  // ambiguous
    found = &m;
  }
  return found;
}

std::vector<const Message*> Database::find_messages(std::string_view name) const {
  std::vector<const Message*> out;
  for (const Message& m : messages)
    if (m.name == name) out.push_back(&m);
  return out;
}

std::string id_text(const Message& m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%X", static_cast<unsigned>(m.is_pseudo ? m.dbc_id : m.id));
  return std::string(buf) + (m.is_pseudo ? " (pseudo)" : m.extended ? " (extended)" : "");
}

std::size_t Database::signal_count() const {
  std::size_t n = 0;
  for (const Message& m : messages) n += m.signals.size();
  return n;
}

std::optional<AttributeValue> attribute_value(const Database& db, const Attributes& own,
                                              std::string_view name) {
  const auto def = db.attribute_definitions.find(name);
  const auto it = own.find(name);
  if (it == own.end()) {
    if (def == db.attribute_definitions.end()) return std::nullopt;
    return def->second.default_value;
  }
  // ENUM values are stored by index in BA_; callers want the name.
  const auto* index = std::get_if<std::int64_t>(&it->second);
  if (def != db.attribute_definitions.end() && def->second.type == AttributeType::Enum &&
      index != nullptr && *index >= 0 &&
      static_cast<std::size_t>(*index) < def->second.enum_values.size())
    return def->second.enum_values[static_cast<std::size_t>(*index)];
  return it->second;
}

}  // namespace dynid::can
