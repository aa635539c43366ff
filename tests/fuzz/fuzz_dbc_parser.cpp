// Fuzz target: the DBC parser (can/dbc.hpp) on arbitrary text. InputError is the documented
// outcome for a bad file; a parsed database must answer its own lookups and decode frames of
// its usable messages without fault (the decoder's contract: it never throws).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "dynid/can/dbc.hpp"
#include "dynid/can/decoder.hpp"
#include "dynid/error.hpp"
#include "fuzz_check.hpp"

namespace {

// One frame per message, of the message's own size, payload from the input's first bytes.
void decode_every_message(const dynid::can::Database& db, std::string_view text) {
  dynid::can::Decoder decoder(db);
  std::vector<dynid::can::DecodedSignal> out;
  for (const auto& message : db.messages) {
    const auto named = db.find_messages(message.name);
    dynid::fuzz::expect(std::find(named.begin(), named.end(), &message) != named.end(),
                        "a parsed message is among the messages of its name");
    dynid::fuzz::expect(db.find_message(message.name) == (named.size() == 1 ? &message : nullptr),
                        "a name finds its message unless several messages have it");
    const bool found_by_id = db.find_message(message.id, message.extended) == &message;
    dynid::fuzz::expect(message.usable() ? found_by_id || message.is_pseudo : !found_by_id,
                        "a usable message, and no other, is found by its id");
    if (!message.usable()) continue;  // its layout may be impossible: never decoded
    dynid::can::Frame frame;
    frame.id = message.id;
    frame.extended = message.extended;
    frame.fd = message.size > dynid::can::Frame::kMaxClassicData;
    frame.length = static_cast<std::uint8_t>(std::min<std::size_t>(message.size, frame.data.size()));
    for (std::size_t k = 0; k < frame.length && k < text.size(); ++k)
      frame.data[k] = static_cast<std::uint8_t>(text[k]);
    decoder.decode(frame, out);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto db = dynid::can::parse_dbc_string(text, "fuzz.dbc");
    decode_every_message(db, text);
  } catch (const dynid::InputError&) {
    // the documented rejection of a bad file
  }
  return 0;
}
