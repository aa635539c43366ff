#pragma once
// Encoding physical values into a frame with a Database message (the reference simulator
// writes CAN logs this way).
//
// Contract:
// - The payload is zeroed, then switches are encoded before the signals they select. A signal
//   whose switch (as encoded) does not select it is not written and is reported as inactive;
//   signals not given stay raw 0.
// - Values outside the raw range are clamped and reported (see physical_to_raw).
// - Throws InputError naming message and signal for an unknown or ambiguous signal name
//   (Message::ambiguous_signals) or a NaN/Inf value, and for an unusable message
//   (Message::problem); the frame is then unchanged.
#include <dynid/can/dbc.hpp>
#include <dynid/can/frame.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::can {

struct SignalValue {
  std::string_view name;
  double value = 0.0;
};

struct EncodeReport {
  std::vector<std::string> clamped;   // signal names whose value did not fit
  std::vector<std::string> inactive;  // given, but not selected by the multiplexer values
  bool ok() const { return clamped.empty() && inactive.empty(); }
};

// Sets frame.id/extended/fd/length (= Message::size) and data; keeps timestamp and interface.
EncodeReport encode_frame(const Message& message, std::span<const SignalValue> values,
                          Frame& frame);

}  // namespace dynid::can
