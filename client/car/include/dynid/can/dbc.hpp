#pragma once
// A CAN database (Vector DBC) held in memory, and its parser.
//
// Contract:
// - parse_dbc_file / parse_dbc_string read the sections real files use: VERSION, NS_, BS_,
//   BU_, BO_ (bit 31 of the id = 29-bit extended id), SG_ (Intel "@1" and Motorola "@0",
//   signed/unsigned, multiplexers "M", "m3", "m3M"), SIG_VALTYPE_ (IEEE float/double),
//   SG_MUL_VAL_ (extended multiplexing ranges), VAL_TABLE_, VAL_, CM_ (multi-line, escaped
//   quotes), BA_DEF_, BA_DEF_DEF_, BA_, BO_TX_BU_, EV_, SIG_GROUP_. Lines end with LF, CRLF or
//   a lone CR (old Mac files); UTF-8 is fine; "//" outside a string comments out the rest of
//   its line (whole lines and trailing comments, as cantools reads them). The other sections of
//   the format (BA_DEF_REL_, SGTYPE_, CAT_, FILTER, ...) are skipped silently.
// - Syntax errors throw dynid::InputError "<name>:<line>: <what>: <reason>": the rest of the
//   file cannot be read with confidence, so nothing of it is returned.
// - A problem confined to one message does not refuse the file: the message is unusable
//   (Message::problem holds the error, naming file:line), Database::warnings says so, and id
//   lookups do not find it (its frames decode as unknown ids). Such problems: an inconsistent
//   layout (signal beyond 64 bytes or outside 1..64 bits, float signal not 32/64 bits, size
//   above 64 bytes, multiplexing without a switch or with a cycle), a signal name repeated in
//   one message where both signals can be present in one frame, an id that another message
//   also has (both are unusable), a line that starts with an unknown word after the message's
//   BO_ or SG_ lines and before any other section (skipped up to the next section keyword; a
//   signal may have been lost there).
//   Derived fields (signal_by_name, decode_order, ...) of an unusable message may be unfilled.
// - A signal name repeated under different values of the same switch (real radar messages do
//   this): every copy decodes when its value is selected; the name is ambiguous
//   (Message::ambiguous_signals, a warning naming the lines) and signal_index does not find it.
//   CM_, VAL_, BA_, SIG_VALTYPE_ and SG_MUL_VAL_ naming it apply to every copy, as in cantools.
// - Two messages with one name: both load and decode by id; a warning names both lines, and
//   find_message(name) finds neither (find_messages lists them).
// - A multiplexed signal no frame can carry (Signal::never_present: a multiplexer value beyond
//   what its switch's bits can hold, a float switch, a switch that is itself never present)
//   leaves its message usable (its other signals decode), with a warning naming its line.
// - Warnings (Database::warnings, "<name>:<line>: ...") also list references to objects the
//   file does not define (CM_/BA_/VAL_ for an unknown message or signal), unknown words at the
//   start of a line outside a message (skipped to the next section keyword), ids interpreted,
//   a missing ';' before the next section, and a file without any message.
// - A vehicle profile (car/vehicle_profile.hpp) that selects an unusable message, a message
//   name that several messages have, an ambiguous signal name or a signal that is never present
//   is refused with the reason and the DBC lines; a profile that does not select them is
//   unaffected.
// - parse_dbc_file reads only a regular file of at most input::kMaxTextFileBytes (a FIFO, a
//   directory or a device is refused: input/input_file.hpp).
// - The returned Database is immutable in use: decoders keep pointers into it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <variant>
#include <vector>

namespace dynid::can {

enum class ByteOrder { Intel, Motorola };     // "@1" little endian, "@0" big endian
enum class ValueType { Integer, Float32, Float64 };  // SIG_VALTYPE_ 0, 1, 2

// An attribute value keeps the type the file gave it: integers (INT, HEX, ENUM index),
// reals (FLOAT) and strings (STRING, or ENUM written by name).
using AttributeValue = std::variant<std::int64_t, double, std::string>;
using Attributes = std::map<std::string, AttributeValue, std::less<>>;

enum class AttributeScope { Network, Node, Message, Signal, EnvVar };
enum class AttributeType { Int, Hex, Float, String, Enum };

struct AttributeDefinition {
  std::string name;
  AttributeScope scope = AttributeScope::Network;
  AttributeType type = AttributeType::String;
  double minimum = 0.0;  // INT/HEX/FLOAT only
  double maximum = 0.0;
  std::vector<std::string> enum_values;        // ENUM only
  std::optional<AttributeValue> default_value;  // BA_DEF_DEF_
};

// Raw values of a multiplexer switch for which a multiplexed signal is present (inclusive).
struct MuxRange {
  std::uint64_t low = 0;
  std::uint64_t high = 0;
};

struct Signal {
  std::string name;
  std::uint32_t start_bit = 0;  // Intel: LSB; Motorola: MSB, in DBC "sawtooth" numbering
  std::uint32_t length = 0;     // bits, 1..64
  ByteOrder byte_order = ByteOrder::Intel;
  bool is_signed = false;
  ValueType value_type = ValueType::Integer;
  double factor = 1.0;
  double offset = 0.0;
  double minimum = 0.0;
  double maximum = 0.0;
  std::string unit;
  std::vector<std::string> receivers;
  std::string comment;
  Attributes attributes;
  std::map<std::int64_t, std::string> value_descriptions;  // VAL_

  // Multiplexing. `is_multiplexer` marks a switch ("M" or "m3M"). A multiplexed signal
  // ("m3", "m3M") is present when its switch (`multiplexer`, the message's only "M" unless
  // SG_MUL_VAL_ names another) holds a raw value in one of `mux_ranges`.
  bool is_multiplexer = false;
  std::optional<std::uint64_t> mux_value;  // the value written in "m<value>"
  std::string multiplexer;                 // name of the switch, empty if not multiplexed
  std::vector<MuxRange> mux_ranges;

  // Filled by the parser: index of the switch signal in the message, or -1.
  int multiplexer_index = -1;
  std::size_t line = 0;  // of its SG_ in the file
  // Filled by the parser: empty when some frame can carry the signal; else why none can,
  // "<name>:<line>: ...": its multiplexer values are beyond what its switch's bits can hold
  // (m300 on an 8-bit switch), its switch is a float signal, or its switch is never present.
  std::string never_present;

  bool is_multiplexed() const { return mux_value.has_value(); }
  bool mux_accepts(std::uint64_t switch_raw) const;
};

struct SignalGroup {
  std::string name;
  std::uint32_t repetitions = 1;
  std::vector<std::string> signals;
};

struct Message {
  std::uint32_t id = 0;  // 11 or 29 bits, without the DBC's bit 31
  bool extended = false;
  std::uint32_t dbc_id = 0;  // as written in the file (bit 31 = extended)
  std::string name;
  std::uint32_t size = 0;  // bytes, 0..64 (CAN FD above 8)
  std::string transmitter;
  std::vector<std::string> extra_transmitters;  // BO_TX_BU_
  std::vector<Signal> signals;
  std::vector<SignalGroup> signal_groups;
  std::string comment;
  Attributes attributes;

  // Filled by the parser.
  std::uint32_t required_bytes = 0;       // smallest payload that holds every signal
  std::vector<std::size_t> decode_order;  // switches before the signals they select
  bool fd = false;                        // VFrameFormat says CAN FD (or size > 8)
  // Vector's VECTOR__INDEPENDENT_SIG_MSG (DBC id 0xC0000000) parks unused signals; it is never
  // on the bus, so id lookups do not find it.
  bool is_pseudo = false;
  std::size_t line = 0;  // of its BO_ in the file

  // Empty when the message can be decoded. Otherwise the error that would have refused the
  // file, "<name>:<line>: <what>: <reason>": the message is unusable (see the contract above).
  std::string problem;
  bool usable() const { return problem.empty(); }

  // Names that several signals of the message carry under different values of their switch,
  // with the lines of their SG_. Those signals decode; signal_index does not find them.
  std::map<std::string, std::vector<std::size_t>, std::less<>> ambiguous_signals;

  // Index of the signal called `name`, or nullopt (also for an ambiguous name). O(1).
  std::optional<std::size_t> signal_index(std::string_view signal_name) const;
  const Signal* find_signal(std::string_view signal_name) const;

  std::unordered_map<std::string, std::size_t> signal_by_name;  // filled by the parser
};

struct Node {
  std::string name;
  std::string comment;
  Attributes attributes;
};

struct EnvironmentVariable {
  std::string name;
  int type = 0;  // 0 integer, 1 float, 2 string
  double minimum = 0.0;
  double maximum = 0.0;
  std::string unit;
  double initial_value = 0.0;
  std::int64_t ev_id = 0;
  std::string access_type;
  std::vector<std::string> access_nodes;
  std::string comment;
  Attributes attributes;
  std::map<std::int64_t, std::string> value_descriptions;
};

// The DBC's own id: 11-bit ids as they are, 29-bit ids with bit 31 set.
constexpr std::uint32_t kDbcExtendedFlag = 0x80000000U;
constexpr std::uint32_t dbc_key(std::uint32_t id, bool extended) {
  return extended ? (id | kDbcExtendedFlag) : id;
}

struct Database {
  std::string source;  // file name or the name given to parse_dbc_string
  std::string version;
  std::vector<std::string> new_symbols;  // NS_
  std::vector<Node> nodes;
  std::map<std::string, std::map<std::int64_t, std::string>, std::less<>> value_tables;
  std::vector<Message> messages;
  std::vector<EnvironmentVariable> environment_variables;
  std::map<std::string, AttributeDefinition, std::less<>> attribute_definitions;
  Attributes network_attributes;
  std::string comment;
  std::vector<std::string> warnings;  // "<name>:<line>: ...", see the contract above

  // Lookup by CAN id, O(1). Returns nullptr for an id the database does not describe, or whose
  // message is unusable.
  const Message* find_message(std::uint32_t id, bool extended) const;
  // Lookup by name: nullptr when no message, or more than one, has that name.
  const Message* find_message(std::string_view name) const;
  // Every message called `name`, in file order (usable or not).
  std::vector<const Message*> find_messages(std::string_view name) const;

  // The DBC id as written (dbc_key, or 0xC0000000 for the pseudo message) -> index.
  std::unordered_map<std::uint32_t, std::size_t> message_by_key;
  std::size_t signal_count() const;
};

// The attribute value of an object, or the definition's default when the object has none.
// ENUM values are returned as their name. nullopt when neither exists.
std::optional<AttributeValue> attribute_value(const Database& db, const Attributes& own,
                                              std::string_view name);

// A message's id for people: "0x1C4", "0x18FFFFFE (extended)", "0xC0000000 (pseudo)".
std::string id_text(const Message& m);

Database parse_dbc_string(std::string_view text, std::string_view name);
Database parse_dbc_file(const std::filesystem::path& path);

}  // namespace dynid::can
