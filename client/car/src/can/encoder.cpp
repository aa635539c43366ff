#include <algorithm>
#include <cmath>
#include <dynid/can/encoder.hpp>
#include <dynid/can/signal_codec.hpp>
#include <dynid/error.hpp>
#include <optional>

namespace dynid::can {
namespace {

// Values by signal index; throws before anything is written, so the frame stays unchanged.
std::vector<std::optional<double>> values_by_index(const Message& m,
                                                   std::span<const SignalValue> values) {
  std::vector<std::optional<double>> out(m.signals.size());
  for (const SignalValue& v : values) {
    const auto i = m.signal_index(v.name);
    if (!i && m.ambiguous_signals.count(v.name) != 0)
      throw InputError("message '" + m.name + "': signal name '" + std::string(v.name) +
                       "' is ambiguous (several SG_ of the message have it)");
    if (!i) throw InputError("message '" + m.name + "': no signal '" + std::string(v.name) + "'");
    if (!std::isfinite(v.value))
      throw InputError("message '" + m.name + "': signal '" + std::string(v.name) +
                       "': value is not finite");
    out[*i] = v.value;
  }
  return out;
}

}  // namespace

EncodeReport encode_frame(const Message& message, std::span<const SignalValue> values,
                          Frame& frame) {
  if (!message.usable())
    throw InputError("message '" + message.name + "' cannot be encoded: " + message.problem);
  const auto given = values_by_index(message, values);
  std::array<std::uint8_t, Frame::kMaxFdData> data{};
  std::vector<bool> active(message.signals.size(), false);
  EncodeReport report;
  for (const std::size_t i : message.decode_order) {
    const Signal& s = message.signals[i];
    if (s.multiplexer_index >= 0) {
      const auto sw = static_cast<std::size_t>(s.multiplexer_index);
      active[i] = active[sw] && s.mux_accepts(extract_raw(message.signals[sw], data));
    } else {
      active[i] = true;
    }
    if (!given[i]) continue;
    if (!active[i]) {
      report.inactive.push_back(s.name);
      continue;
    }
    const RawEncoding enc = physical_to_raw(s, *given[i]);
    if (enc.clamped) report.clamped.push_back(s.name);
    insert_raw(s, enc.raw, data);
  }
  frame.id = message.id;
  frame.extended = message.extended;
  frame.length = static_cast<std::uint8_t>(std::max(message.size, message.required_bytes));
  frame.fd = message.fd || frame.length > Frame::kMaxClassicData;
  frame.rtr = false;
  frame.data = data;
  return report;
}

}  // namespace dynid::can
