#include "dynid/sim/sensors.hpp"

#include <string>

#include "dynid/sim/channels.hpp"

namespace dynid::sim {
namespace {

std::uint64_t fnv1a(std::string_view text, std::uint64_t seed) {
  std::uint64_t h = 14695981039346656037ULL ^ seed;
  for (char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ULL;
  }
  return h;
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

double normal(std::mt19937_64& g) { return std::normal_distribution<double>(0.0, 1.0)(g); }

}  // namespace

SensorSpec default_sensor(std::string_view c) {
  // The ESP's vehicle speed is the mean of its four wheel-speed sensors (DBC comment of
  // VehSpeed): half the noise of one wheel speed.
  if (c == "vx") return {0.01, 0.0};
  if (starts_with(c, "wheel_speed_")) return {0.02, 0.0};
  // Ride-height lasers (0.2 mm noise, ~1 mm zero error each, over a 1.5 m track).
  if (c == "roll") return {2e-4, 7e-4};
  if (c == "vy") return {0.03, 0.02};
  if (c == "ax" || c == "ay" || c == "az") return {0.05, 0.05};
  if (c == "roll_rate" || c == "pitch_rate" || c == "yaw_rate") return {0.002, 0.003};
  if (c == "steer") return {2e-4, 1e-3};
  if (c == "engine_speed" || c == "gearbox_input_speed") return {0.5, 0.0};
  if (c == "engine_torque") return {2.0, 3.0};
  if (c == "clutch_clamp_load") return {30.0, 50.0};
  if (c == "wheel_torque") return {5.0, 5.0};
  if (c == "brake_pressure") return {2000.0, 0.0};
  if (c == "road_grade" || c == "road_bank") return {0.002, 0.001};
  if (starts_with(c, "susp_travel_")) return {5e-4, 1e-3};
  if (starts_with(c, "susp_force_")) return {20.0, 20.0};
  if (starts_with(c, "hub_")) return {25.0, 10.0};
  if (starts_with(c, "tyre_deflection_")) return {1e-4, 2e-4};
  if (starts_with(c, "tyre_force_z_")) return {25.0, 10.0};
  return {};
}

SensorBank::SensorBank(std::uint64_t seed, const Effects& effects, double noise_scale,
                       const std::map<std::string, double>& gains)
    : noise_(effects.sensor_noise), noise_scale_(noise_scale) {
  for (const auto& c : channel_catalogue()) {
    const auto gain = gains.find(c.name);
    gains_.push_back(gain == gains.end() ? 1.0 : gain->second);
    specs_.push_back(default_sensor(c.name));
    streams_.emplace_back(fnv1a(c.name, seed));
    // The offset comes from its own stream, so the noise sequence does not depend on it.
    std::mt19937_64 offset_stream(fnv1a(c.name + "#offset", seed));
    offsets_.push_back(effects.sensor_offsets ? specs_.back().offset_sigma * normal(offset_stream) : 0.0);
  }
}

double SensorBank::measure(std::size_t channel, double true_value) {
  const SensorSpec& spec = specs_[channel];
  double value = gains_[channel] * true_value + offsets_[channel];
  if (noise_ && spec.noise > 0.0) value += noise_scale_ * spec.noise * normal(streams_[channel]);
  return value;
}

}  // namespace dynid::sim
