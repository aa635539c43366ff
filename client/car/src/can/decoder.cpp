#include <dynid/can/decoder.hpp>
#include <dynid/can/signal_codec.hpp>
#include <sstream>

namespace dynid::can {

std::string_view to_string(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::Ok: return "ok";
    case DecodeStatus::UnknownId: return "unknown id";
    case DecodeStatus::RemoteFrame: return "remote frame (no data)";
    case DecodeStatus::ShortPayload: return "payload too short";
  }
  return "?";
}

DecodeResult Decoder::decode(const Frame& frame, std::vector<DecodedSignal>& out) {
  out.clear();
  ++stats_.frames;
  DecodeResult result;
  result.message = db_.find_message(frame.id, frame.extended);
  if (result.message == nullptr) {
    ++stats_.unknown_id;
    result.status = DecodeStatus::UnknownId;
    return result;
  }
  const Message& m = *result.message;
  if (frame.rtr) {
    ++stats_.remote;
    result.status = DecodeStatus::RemoteFrame;
    return result;
  }
  if (frame.length < m.required_bytes) {
    ++stats_.short_payload;
    result.status = DecodeStatus::ShortPayload;
    return result;
  }
  result.length_mismatch = frame.length != m.size;
  stats_.length_mismatch += result.length_mismatch ? 1 : 0;
  ++stats_.decoded;

  slot_.assign(m.signals.size(), -1);
  for (const std::size_t i : m.decode_order) {
    const Signal& s = m.signals[i];
    if (s.multiplexer_index >= 0) {
      // The switch precedes this signal in decode_order, so its slot is final.
      const int sw = slot_[static_cast<std::size_t>(s.multiplexer_index)];
      if (sw < 0 || !s.mux_accepts(out[static_cast<std::size_t>(sw)].raw)) continue;
    }
    const std::uint64_t raw = extract_raw(s, frame.payload());
    slot_[i] = static_cast<int>(out.size());
    out.push_back(DecodedSignal{i, &s, raw, raw_to_physical(s, raw)});
  }
  return result;
}

std::string explain(const Frame& frame, const DecodeResult& result) {
  if (result.status == DecodeStatus::Ok) return {};
  std::ostringstream os;
  os << "frame 0x" << std::hex << std::uppercase << frame.id << std::dec
     << (frame.extended ? " (extended)" : "") << " on '" << frame.interface_name()
     << "' at t=" << frame.timestamp << ": " << to_string(result.status);
  if (result.status == DecodeStatus::ShortPayload)
    os << ": payload has " << int{frame.length} << " bytes, message '" << result.message->name
       << "' needs " << result.message->required_bytes;
  return os.str();
}

}  // namespace dynid::can
