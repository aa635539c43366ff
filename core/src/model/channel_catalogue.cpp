#include "dynid/model/channel_catalogue.hpp"

#include <map>

namespace dynid::model {
namespace {

constexpr const char* kCorners[] = {"fl", "fr", "rl", "rr"};

std::vector<std::pair<std::string, std::string>> make_catalogue() {
  std::vector<std::pair<std::string, std::string>> c{{"vx", "m/s"}, {"vy", "m/s"}};
  for (const char* w : kCorners) c.emplace_back(std::string("wheel_speed_") + w, "m/s");
  for (const char* n : {"ax", "ay", "az"}) c.emplace_back(n, "m/s^2");
  for (const char* n : {"roll_rate", "pitch_rate", "yaw_rate"}) c.emplace_back(n, "rad/s");
  c.insert(c.end(), {{"steer", "rad"},
                     {"engine_speed", "rad/s"},
                     {"engine_torque", "N m"},
                     {"gearbox_input_speed", "rad/s"},
                     {"gear", "-"},
                     {"gear_ratio", "-"},
                     {"clutch_clamp_load", "N"},
                     {"wheel_torque", "N m"},
                     {"brake_pressure", "Pa"},
                     {"road_grade", "rad"},
                     {"road_bank", "rad"},
                     {"roll", "rad"}});
  for (const char* w : kCorners) {
    c.emplace_back(std::string("susp_travel_") + w, "m");
    c.emplace_back(std::string("susp_force_") + w, "N");
    for (const char* f : {"hub_fx_", "hub_fy_", "hub_fz_"}) c.emplace_back(std::string(f) + w, "N");
    for (const char* m : {"hub_mx_", "hub_my_", "hub_mz_"}) c.emplace_back(std::string(m) + w, "N m");
    c.emplace_back(std::string("tyre_deflection_") + w, "m");
    c.emplace_back(std::string("tyre_force_z_") + w, "N");
  }
  return c;
}

const std::map<std::string, std::string, std::less<>>& units() {
  static const auto table = [] {
    std::map<std::string, std::string, std::less<>> t;
    for (auto& [name, unit] : make_catalogue()) t.emplace(name, unit);
    return t;
  }();
  return table;
}

// docs/CHANNELS.md: the unit of d_<name> is the unit of <name> per second.
std::optional<std::string> per_second(const std::string& unit) {
  if (unit == "m/s") return "m/s^2";
  if (unit == "rad/s") return "rad/s^2";
  if (unit == "m" || unit == "rad") return unit + "/s";
  return std::nullopt;
}

}  // namespace

std::optional<std::string> channel_unit(std::string_view channel) {
  if (auto it = units().find(channel); it != units().end()) return it->second;
  if (channel.starts_with("d_")) {
    if (auto it = units().find(channel.substr(2)); it != units().end()) return per_second(it->second);
  }
  return std::nullopt;
}

const std::vector<std::string>& channel_names() {
  static const auto names = [] {
    std::vector<std::string> n;
    for (auto& entry : make_catalogue()) n.push_back(entry.first);
    return n;
  }();
  return names;
}

}  // namespace dynid::model
