#pragma once
// Checks and derived fields that need the whole file (private to the parser).
#include <cstddef>
#include <cstdint>
#include <dynid/can/dbc.hpp>
#include <string>
#include <vector>

namespace dynid::can::detail {

// The key under which a BO_ id is stored and referenced (Database::message_by_key): the DBC
// id, except that ids above 0x7FF written without bit 31 (common in opendbc) get bit 31, since
// only a 29-bit frame can carry them.
std::uint32_t message_key(std::uint32_t raw_id);

// Splits the DBC id (bit 31 = extended) into id and flag. Ids that no frame can carry (Vector's
// VECTOR__INDEPENDENT_SIG_MSG, more than 29 bits) make a pseudo message. Returns a warning
// for ids it had to interpret, else "".
std::string set_message_id(Message& m, std::uint32_t raw_id);

// Bytes [first, last] a signal occupies; throws nothing, assumes start/length were checked.
struct ByteSpan {
  std::uint32_t first = 0;
  std::uint32_t last = 0;
};
ByteSpan signal_bytes(const Signal& s);

// Validates layouts and multiplexing, fills Message::required_bytes, decode_order, fd,
// signal_by_name, ambiguous_signals and Signal::multiplexer_index. A message with a problem
// (found here or by the parser) is left unusable, with a warning, and out of the id index;
// messages that share a name get a warning. Throws nothing for a message's problem.
void finalize_database(Database& db, std::size_t last_line);

}  // namespace dynid::can::detail
