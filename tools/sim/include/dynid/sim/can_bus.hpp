#pragma once
// The simulated car's CAN bus: which DBC signal carries which channel (with the unit conversion
// a real car's DBC needs: km/h, deg/s, rpm, bar, steering-wheel degrees, mm), when each message
// is sent (its DBC GenMsgCycleTime), and the frames themselves.
//
// Contract: the bus is built against a parsed DBC (deploy/dbc/dynid_testcar.dbc); every binding
// must name a message and signal of it, else InputError. Message periods must be whole
// multiples of the integration step (checked by the simulator). quantize() returns the SI value
// a receiver decodes after encoding, i.e. the signal's resolution; encode() fills the frame from
// measured SI values, plus the messages' rolling counters and checksums.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <dynid/can/dbc.hpp>
#include <dynid/can/frame.hpp>

#include "dynid/sim/parameters.hpp"

namespace dynid::sim {

struct CanBinding {
  std::string channel;
  std::string message;
  std::string signal;
  double to_dbc = 1.0;  // DBC physical value = SI value * to_dbc
};

std::vector<CanBinding> can_bindings(const VehicleParameters& vehicle);

struct ScheduledMessage {
  const can::Message* message = nullptr;
  double period = 0.0;  // s
  double phase = 0.0;   // s, first transmission
  std::vector<std::size_t> bindings;  // indices into CanBus::bindings()
};

class CanBus {
 public:
  CanBus(const can::Database& db, std::vector<CanBinding> bindings);

  const std::vector<CanBinding>& bindings() const { return bindings_; }
  const std::vector<ScheduledMessage>& schedule() const { return schedule_; }
  // Binding index and channel index (channel_catalogue) of each binding.
  std::size_t channel_of(std::size_t binding) const { return channel_of_[binding]; }
  std::optional<std::size_t> binding_of_channel(std::size_t channel) const;

  double quantize(std::size_t binding, double value) const;
  // `measured` is indexed like channel_catalogue().
  can::Frame encode(std::size_t scheduled, const std::vector<double>& measured, double timestamp,
                    const std::string& interface_name, std::uint32_t counter) const;

 private:
  const can::Signal& signal(std::size_t binding) const;

  std::vector<CanBinding> bindings_;
  std::vector<std::size_t> channel_of_;
  std::vector<const can::Message*> message_of_;
  std::vector<ScheduledMessage> schedule_;
};

}  // namespace dynid::sim
