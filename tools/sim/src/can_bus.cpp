#include "dynid/sim/can_bus.hpp"

#include <cmath>
#include <numbers>
#include <string_view>

#include <dynid/can/encoder.hpp>
#include <dynid/can/signal_codec.hpp>

#include "dynid/error.hpp"
#include "dynid/sim/channels.hpp"

namespace dynid::sim {
namespace {

constexpr double kKmh = 3.6;                             // m/s -> km/h
constexpr double kDeg = 180.0 / std::numbers::pi;        // rad -> deg
constexpr double kRpm = 60.0 / (2.0 * std::numbers::pi); // rad/s -> rpm
constexpr double kBar = 1e-5;                            // Pa -> bar
constexpr double kMm = 1e3;                              // m -> mm
constexpr double kDefaultPeriodMs = 100.0;

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::string upper(const char* corner) {
  std::string s(corner);
  for (char& c : s) c = static_cast<char>(c - 'a' + 'A');
  return s;
}

double cycle_time_ms(const can::Database& db, const can::Message& m) {
  const auto v = can::attribute_value(db, m.attributes, "GenMsgCycleTime");
  if (!v) return kDefaultPeriodMs;
  if (const auto* i = std::get_if<std::int64_t>(&*v)) return static_cast<double>(*i);
  if (const auto* d = std::get_if<double>(&*v)) return *d;
  return kDefaultPeriodMs;
}

}  // namespace

std::vector<CanBinding> can_bindings(const VehicleParameters& vehicle) {
  std::vector<CanBinding> b;
  for (const char* w : kCornerNames) {
    const std::string W = upper(w);
    b.push_back({std::string("wheel_speed_") + w, "ESP_WheelSpeeds", "WhlSpd_" + W, kKmh});
    b.push_back({std::string("susp_travel_") + w, "TI_SuspTravel", "SuspTravel_" + W, kMm});
    b.push_back({std::string("susp_force_") + w, "TI_SuspForce", "SuspForce_" + W, 1.0});
    b.push_back({std::string("hub_fx_") + w, "TI_Hub_" + W, "HubFx_" + W, 1.0});
    b.push_back({std::string("hub_fy_") + w, "TI_Hub_" + W, "HubFy_" + W, 1.0});
    b.push_back({std::string("hub_fz_") + w, "TI_Hub_" + W, "HubFz_" + W, 1.0});
    b.push_back({std::string("tyre_deflection_") + w, "TI_TyreDeflection", "TyreDefl_" + W, kMm});
    b.push_back({std::string("tyre_force_z_") + w, "TI_TyreLoad", "TyreFz_" + W, 1.0});
  }
  b.insert(b.end(), {
      {"yaw_rate", "ESP_Dynamics", "YawRate", kDeg},
      {"ay", "ESP_Dynamics", "LatAccel", 1.0},
      {"ax", "ESP_Dynamics", "LongAccel", 1.0},
      {"vx", "ESP_Dynamics", "VehSpeed", kKmh},
      {"steer", "SAS_Steering", "SteerWheelAngle", kDeg * vehicle.steering_ratio},
      {"engine_speed", "ECM_Engine1", "EngSpeed", kRpm},
      {"engine_torque", "ECM_Engine1", "EngTorque", 1.0},
      {"gearbox_input_speed", "TCU_Status", "InputShaftSpeed", kRpm},
      {"gear", "TCU_Status", "GearEngaged", 1.0},
      {"clutch_clamp_load", "TCU_Status", "ClutchClampLoad", 1.0},
      {"brake_pressure", "BRK_Status", "BrakePressure", kBar},
      {"road_grade", "GNSS_RoadPose", "RoadGrade", 1.0},
      {"road_bank", "GNSS_RoadPose", "RoadBank", 1.0},
      {"roll_rate", "TI_IMU", "RollRate", kDeg},
      {"pitch_rate", "TI_IMU", "PitchRate", kDeg},
      {"az", "TI_IMU", "VertAccel", 1.0},
      {"vy", "TI_Optical", "VelLat", kKmh},
      {"wheel_torque", "TI_WheelTorque", "DrivenWheelTorque", 1.0},
      {"roll", "TI_RideHeight", "BodyRoll", kDeg},
  });
  return b;
}

CanBus::CanBus(const can::Database& db, std::vector<CanBinding> bindings) : bindings_(std::move(bindings)) {
  for (std::size_t i = 0; i < bindings_.size(); ++i) {
    const auto& b = bindings_[i];
    const can::Message* m = db.find_message(b.message);
    if (m == nullptr) throw InputError(db.source + ": no message '" + b.message + "' for channel " + b.channel);
    if (m->find_signal(b.signal) == nullptr)
      throw InputError(db.source + ": message " + b.message + " has no signal '" + b.signal + "'");
    channel_of_.push_back(channel_index(b.channel));
    message_of_.push_back(m);
  }
  // One schedule entry per message, in DBC order; phases staggered by 1 ms like real ECUs.
  for (const auto& m : db.messages) {
    ScheduledMessage s;
    s.message = &m;
    for (std::size_t i = 0; i < bindings_.size(); ++i)
      if (message_of_[i] == &m) s.bindings.push_back(i);
    if (s.bindings.empty()) continue;
    s.period = cycle_time_ms(db, m) * 1e-3;
    s.phase = std::fmod(1e-3 * static_cast<double>(schedule_.size()), s.period);
    schedule_.push_back(std::move(s));
  }
}

std::optional<std::size_t> CanBus::binding_of_channel(std::size_t channel) const {
  for (std::size_t i = 0; i < channel_of_.size(); ++i)
    if (channel_of_[i] == channel) return i;
  return std::nullopt;
}

const can::Signal& CanBus::signal(std::size_t binding) const {
  return *message_of_[binding]->find_signal(bindings_[binding].signal);
}

double CanBus::quantize(std::size_t binding, double value) const {
  const can::Signal& s = signal(binding);
  const double to_dbc = bindings_[binding].to_dbc;
  return can::raw_to_physical(s, can::physical_to_raw(s, value * to_dbc).raw) / to_dbc;
}

can::Frame CanBus::encode(std::size_t scheduled, const std::vector<double>& measured, double timestamp,
                          const std::string& interface_name, std::uint32_t counter) const {
  const ScheduledMessage& sm = schedule_[scheduled];
  std::vector<can::SignalValue> values;
  for (std::size_t b : sm.bindings)
    values.push_back({bindings_[b].signal, measured[channel_of_[b]] * bindings_[b].to_dbc});
  // Signals no channel carries but a real message has: counters and the pedal switch.
  for (const auto& s : sm.message->signals) {
    if (ends_with(s.name, "_Counter")) values.push_back({s.name, static_cast<double>(counter % 16U)});
    if (s.name == "BrakePedalPressed")
      values.push_back({s.name, measured[channel_index("brake_pressure")] > 1e5 ? 1.0 : 0.0});
  }
  can::Frame frame;
  frame.timestamp = timestamp;
  frame.set_interface_name(interface_name);
  can::encode_frame(*sm.message, values, frame);
  for (const auto& s : sm.message->signals) {
    if (!ends_with(s.name, "_Checksum")) continue;
    unsigned sum = 0;
    for (std::size_t i = 0; i + 1 < frame.length; ++i) sum += frame.data[i];
    can::insert_raw(s, sum % 256U, std::span<std::uint8_t>(frame.data.data(), frame.length));
  }
  return frame;
}

}  // namespace dynid::sim
