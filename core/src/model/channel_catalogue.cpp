#include "dynid/model/channel_catalogue.hpp"

#include <map>

namespace dynid::model {
namespace {

constexpr const char* kCorners[] = {"fl", "fr", "rl", "rr"};

struct Entry {
  std::string name;
  std::string unit;
  ChannelPhysics physics;
};

// The ranges are impossibilities on a passenger car or light truck, wide on purpose (a value
// outside is a decoding or sensor fault, never a hard manoeuvre): docs/CHANNELS.md has the table.
std::vector<Entry> make_catalogue() {
  constexpr double kSpeed = 120.0;        // m/s, 432 km/h
  constexpr double kAcceleration = 50.0;  // m/s^2, 5 g
  constexpr double kRate = 20.0;          // rad/s, a body spinning 3 turns a second
  constexpr double kShaftSpeed = 1600.0;  // rad/s, 15 000 rpm
  constexpr double kAngle = 1.5;          // rad, 86 degrees
  constexpr double kForce = 1e5;          // N, ten tonnes on one corner
  constexpr double kGravity = 9.80665;    // m/s^2: `az` at rest reads +g (specific force)
  constexpr bool kRestOnly = true;
  constexpr bool kInertial = true;
  std::vector<Entry> c{{"vx", "m/s", {-kSpeed, kSpeed}}, {"vy", "m/s", {-kSpeed, kSpeed}}};
  for (const char* w : kCorners)
    c.push_back({std::string("wheel_speed_") + w, "m/s", {-kSpeed, kSpeed}});
  c.push_back({"ax", "m/s^2", {-kAcceleration, kAcceleration, 0.0, kRestOnly, kInertial}});
  c.push_back({"ay", "m/s^2", {-kAcceleration, kAcceleration, 0.0, false, kInertial}});
  c.push_back({"az", "m/s^2", {-kAcceleration, kAcceleration, kGravity, kRestOnly, kInertial}});
  for (const char* n : {"roll_rate", "pitch_rate"})
    c.push_back({n, "rad/s", {-kRate, kRate, 0.0, kRestOnly, kInertial}});
  c.push_back({"yaw_rate", "rad/s", {-kRate, kRate, 0.0, false, kInertial}});
  c.insert(c.end(), {{"steer", "rad", {-kAngle, kAngle}},
                     {"engine_speed", "rad/s", {-kShaftSpeed, kShaftSpeed}},
                     {"engine_torque", "N m", {-5000.0, 5000.0}},
                     {"gearbox_input_speed", "rad/s", {-kShaftSpeed, kShaftSpeed}},
                     {"gear", "-", {-2.0, 20.0}},
                     {"gear_ratio", "-", {-100.0, 100.0}},
                     {"clutch_clamp_load", "N", {-kForce, kForce}},
                     {"clutch_engagement", "-", {-0.5, 1.5}},
                     {"wheel_torque", "N m", {-30000.0, 30000.0}},
                     {"brake_pressure", "Pa", {-1e6, 5e7}},
                     {"road_grade", "rad", {-0.6, 0.6}},
                     {"road_bank", "rad", {-0.6, 0.6}},
                     {"roll", "rad", {-0.6, 0.6}}});
  for (const char* w : kCorners) {
    c.push_back({std::string("susp_travel_") + w, "m", {-0.5, 0.5}});
    c.push_back({std::string("susp_force_") + w, "N", {-kForce, kForce}});
    for (const char* f : {"hub_fx_", "hub_fy_", "hub_fz_"})
      c.push_back({std::string(f) + w, "N", {-kForce, kForce}});
    for (const char* m : {"hub_mx_", "hub_my_", "hub_mz_"})
      c.push_back({std::string(m) + w, "N m", {-3e4, 3e4}});
    c.push_back({std::string("tyre_deflection_") + w, "m", {-0.2, 0.2}});
    c.push_back({std::string("tyre_force_z_") + w, "N", {-kForce, kForce}});
  }
  return c;
}

const std::map<std::string, Entry, std::less<>>& entries() {
  static const auto table = [] {
    std::map<std::string, Entry, std::less<>> t;
    for (auto& entry : make_catalogue()) t.emplace(entry.name, entry);
    return t;
  }();
  return table;
}

// docs/CHANNELS.md: the unit of d_<name> is the unit of <name> per second.
std::optional<std::string> per_second(const std::string& unit) {
  if (unit == "m/s") return "m/s^2";
  if (unit == "m/s^2") return "m/s^2/s";  // as the server names d_ay's unit
  if (unit == "rad/s") return "rad/s^2";
  if (unit == "m" || unit == "rad") return unit + "/s";
  return std::nullopt;
}

}  // namespace

std::optional<std::string> channel_unit(std::string_view channel) {
  if (auto it = entries().find(channel); it != entries().end()) return it->second.unit;
  if (channel.starts_with("d_")) {
    if (auto it = entries().find(channel.substr(2)); it != entries().end())
      return per_second(it->second.unit);
  }
  return std::nullopt;
}

std::optional<ChannelPhysics> channel_physics(std::string_view channel) {
  if (auto it = entries().find(channel); it != entries().end()) return it->second.physics;
  return std::nullopt;
}

const std::vector<std::string>& channel_names() {
  static const auto names = [] {
    std::vector<std::string> n;
    for (auto& entry : make_catalogue()) n.push_back(entry.name);
    return n;
  }();
  return names;
}

}  // namespace dynid::model
