#pragma once
// Decoding frames into physical signal values with a Database.
//
// Contract:
// - Lookup of the frame's (id, extended) is O(1). The Database must outlive the Decoder.
// - Only signals active under the current multiplexer values are decoded: a multiplexed
//   signal is active when its switch is active and the switch's raw value is in one of the
//   signal's ranges (extended multiplexing chains switches).
// - Nothing here throws on bad frames; the result says what happened and the Decoder counts:
//   UnknownId: no message with that id (and extended flag) in the database.
//   RemoteFrame: RTR frames carry no data.
//   ShortPayload: fewer bytes than the message's signals need (Message::required_bytes).
//   A payload whose length differs from the DBC size but holds every signal is decoded, and
//   counted in DecodeStats::length_mismatch (real logs pad payloads to 8 bytes).
#include <cstddef>
#include <cstdint>
#include <dynid/can/dbc.hpp>
#include <dynid/can/frame.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::can {

enum class DecodeStatus { Ok, UnknownId, RemoteFrame, ShortPayload };
std::string_view to_string(DecodeStatus status);

struct DecodedSignal {
  std::size_t index = 0;  // in Message::signals
  const Signal* signal = nullptr;
  std::uint64_t raw = 0;  // the bit pattern
  double value = 0.0;     // physical
};

struct DecodeResult {
  DecodeStatus status = DecodeStatus::Ok;
  const Message* message = nullptr;  // set unless UnknownId
  bool length_mismatch = false;      // decoded although the length differs from the DBC size
};

struct DecodeStats {
  std::uint64_t frames = 0;
  std::uint64_t decoded = 0;
  std::uint64_t unknown_id = 0;
  std::uint64_t remote = 0;
  std::uint64_t short_payload = 0;
  std::uint64_t length_mismatch = 0;
};

class Decoder {
 public:
  explicit Decoder(const Database& db) : db_(db) {}

  // Fills `out` (cleared first; reuse it across calls so the hot path does not allocate) with
  // the active signals, switches before the signals they select.
  DecodeResult decode(const Frame& frame, std::vector<DecodedSignal>& out);

  const DecodeStats& stats() const { return stats_; }
  const Database& database() const { return db_; }

 private:
  const Database& db_;
  DecodeStats stats_;
  std::vector<int> slot_;  // signal index -> position in `out`, -1 when inactive
};

// A sentence for logs: "<name>: frame 0x1C4 (can0, t=...): payload has 3 bytes, message
// 'ENGINE_RPM' needs 5". Empty for Ok.
std::string explain(const Frame& frame, const DecodeResult& result);

}  // namespace dynid::can
