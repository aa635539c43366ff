#include "dynid/residual/sensor_offset.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "dynid/error.hpp"
#include "dynid/input/number.hpp"

namespace dynid::residual {
namespace {

constexpr const char* kPrefix = "offset:";
constexpr double kGravity = 9.80665;  // m/s^2, standard gravity

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

bool is_offset_effect(const std::string& name) { return name.rfind(kPrefix, 0) == 0; }

SensorOffset parse_offset_effect(const std::string& name) {
  const std::string form = "effect '" + name + "': expected offset:<channel>@<value in the channel's unit>";
  if (!is_offset_effect(name)) throw InputError(form);
  const std::string rest = name.substr(std::string(kPrefix).size());
  const auto at = rest.rfind('@');
  if (at == std::string::npos || at == 0 || at + 1 == rest.size()) throw InputError(form);
  std::string number = rest.substr(at + 1);
  if (number.size() > 1 && number.front() == '+') number.erase(0, 1);  // offset_effect_name writes the sign
  const std::optional<double> value = input::parse_finite(number);
  if (!value) throw InputError("effect '" + name + "': '" + rest.substr(at + 1) + "' is not a finite number");
  return {rest.substr(0, at), *value};
}

std::string offset_effect_name(const std::string& channel, double value) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%+.6g", value);
  return kPrefix + channel + "@" + buf;
}

bool is_mounted_sensor(const std::string& channel, const std::string& unit) {
  if (channel.rfind("d_", 0) == 0) return false;  // a derivative the preprocessing makes, no sensor
  return unit == "m/s^2" || (unit == "rad/s" && ends_with(channel, "_rate"));
}

std::string offset_finding(const std::string& channel, const std::string& unit, double value, double std) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s reads %+.4g +- %.2g %s too much", channel.c_str(), value, std, unit.c_str());
  std::string out = buf;
  if (unit != "m/s^2" || std::abs(value) >= kGravity) return out;
  // Tilted by a small angle a, the axis reads g sin(a) of gravity: a = asin(offset / g), and its
  // std through the derivative 1 / sqrt(g^2 - offset^2).
  const double degrees = 180.0 / std::numbers::pi;
  const double angle = std::asin(value / kGravity) * degrees;
  const double angle_std = std / std::sqrt(kGravity * kGravity - value * value) * degrees;
  const char* tilt = channel == "ax" ? "pitched" : channel == "ay" ? "rolled" : "tilted";
  std::snprintf(buf, sizeof buf, ": the accelerometer %s %+.2f +- %.2f deg on its mount (g sin(angle))", tilt, angle,
                angle_std);
  return out + buf;
}

std::vector<ingest::PreprocessedSegment> offset_corrected(const std::vector<ingest::PreprocessedSegment>& run,
                                                          const std::vector<SensorOffset>& offsets) {
  std::vector<ingest::PreprocessedSegment> out = run;
  for (ingest::PreprocessedSegment& s : out)
    for (const SensorOffset& o : offsets) {
      if (!s.channels.has(o.channel))
        throw InputError("effect '" + offset_effect_name(o.channel, o.value) + "': the run has no channel '" +
                         o.channel + "'");
      s.channels.replace(o.channel, s.channels[o.channel].array() - o.value);
    }
  return out;
}

}  // namespace dynid::residual
