#include "dynid/car/signal_mapper.hpp"

#include <cmath>
#include <limits>

namespace dynid::car {

SignalMapper::SignalMapper(const VehicleProfile& profile) : profile_(profile), decoder_(*profile.dbc) {
  for (std::size_t c = 0; c < profile_.channels.size(); ++c) {
    if (profile_.channels[c].source) continue;  // an auxiliary source's
    if (profile_.channels[c].constant)
      constants_.push_back(c);
    else
      channels_of_[profile_.channels[c].dbc_message].push_back(c);  // bus channels
  }
}

FrameOutcome SignalMapper::map(const can::Frame& frame, std::vector<ChannelSample>& out) {
  ++stats_.frames;
  if (!usable_time(frame.timestamp)) {
    ++stats_.bad_time;
    return FrameOutcome::BadTime;
  }
  // Another bus may reuse an id of this DBC with another meaning (the RAV4's radar bus does).
  if (!profile_.accepts_interface(frame.interface_name())) {
    ++stats_.other_interface;
    return FrameOutcome::OtherInterface;
  }
  const can::DecodeResult r = decoder_.decode(frame, decoded_);
  switch (r.status) {
    case can::DecodeStatus::UnknownId: ++stats_.unknown_id; return FrameOutcome::UnknownId;
    case can::DecodeStatus::RemoteFrame: ++stats_.remote; return FrameOutcome::RemoteFrame;
    case can::DecodeStatus::ShortPayload: ++stats_.short_payload; return FrameOutcome::ShortPayload;
    case can::DecodeStatus::Ok: break;
  }
  const auto it = channels_of_.find(r.message);
  if (it == channels_of_.end()) {
    ++stats_.unmapped;
    return FrameOutcome::Unmapped;
  }
  ++stats_.mapped;
  // Inactive (multiplexed-out) signals stay NaN, so a channel reading one yields no sample.
  physical_.assign(r.message->signals.size(), std::numeric_limits<double>::quiet_NaN());
  for (const auto& d : decoded_) physical_[d.index] = d.value;
  for (std::size_t c : it->second) {
    const double v = profile_.channels[c].value(physical_);
    if (!dropped_.keep(c, frame.timestamp, v)) {
      ++(std::isfinite(v) ? stats_.out_of_range : stats_.non_finite);
      continue;
    }
    out.push_back({c, frame.timestamp, v});
  }
  for (std::size_t c : constants_)
    out.push_back({c, frame.timestamp, *profile_.channels[c].constant});
  return FrameOutcome::Mapped;
}

}  // namespace dynid::car
