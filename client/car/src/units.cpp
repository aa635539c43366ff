#include "dynid/car/units.hpp"

#include <numbers>
#include <string>

namespace dynid::car {
namespace {

// A spelling, the quantity it measures, and its SI equivalent: si = value * factor + offset.
struct UnitInfo {
  std::string_view spelling;
  std::string_view quantity;
  double factor;
  double offset;
};

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kRpm = 2.0 * std::numbers::pi / 60.0;
constexpr double kG = 9.80665;

// Spellings seen in real DBC files (opendbc, OEM files) next to the catalogue's own SI strings.
constexpr UnitInfo kUnits[] = {
    {"m/s", "speed", 1.0, 0.0},           {"km/h", "speed", 1.0 / 3.6, 0.0},
    {"kph", "speed", 1.0 / 3.6, 0.0},     {"kmh", "speed", 1.0 / 3.6, 0.0},
    {"Km/h", "speed", 1.0 / 3.6, 0.0},    {"mph", "speed", 0.44704, 0.0},
    {"rad", "angle", 1.0, 0.0},           {"deg", "angle", kDeg, 0.0},
    {"degree", "angle", kDeg, 0.0},       {"°", "angle", kDeg, 0.0},
    {"rad/s", "rate", 1.0, 0.0},          {"deg/s", "rate", kDeg, 0.0},
    {"°/s", "rate", kDeg, 0.0},           {"rpm", "rate", kRpm, 0.0},
    {"RPM", "rate", kRpm, 0.0},           {"1/min", "rate", kRpm, 0.0},
    {"m/s^2", "acceleration", 1.0, 0.0},  {"m/s2", "acceleration", 1.0, 0.0},
    {"m/s²", "acceleration", 1.0, 0.0},   {"g", "acceleration", kG, 0.0},
    {"m", "length", 1.0, 0.0},            {"cm", "length", 0.01, 0.0},
    {"mm", "length", 1e-3, 0.0},          {"N", "force", 1.0, 0.0},
    {"kN", "force", 1e3, 0.0},            {"N m", "torque", 1.0, 0.0},
    {"Nm", "torque", 1.0, 0.0},           {"N.m", "torque", 1.0, 0.0},
    {"kNm", "torque", 1e3, 0.0},          {"Pa", "pressure", 1.0, 0.0},
    {"kPa", "pressure", 1e3, 0.0},        {"bar", "pressure", 1e5, 0.0},
    {"mbar", "pressure", 100.0, 0.0},     {"psi", "pressure", 6894.757293168, 0.0},
    {"-", "ratio", 1.0, 0.0},             {"%", "ratio", 0.01, 0.0},
    {"m/s^3", "jerk", 1.0, 0.0},          {"rad/s^2", "angular acceleration", 1.0, 0.0},
    {"deg/s^2", "angular acceleration", kDeg, 0.0},
};

const UnitInfo* find(std::string_view unit) {
  for (const auto& u : kUnits)
    if (u.spelling == unit) return &u;
  return nullptr;
}

}  // namespace

bool known_unit(std::string_view unit) { return find(unit) != nullptr; }

std::optional<LinearConversion> conversion(std::string_view from, std::string_view to) {
  const UnitInfo* f = find(from);
  const UnitInfo* t = find(to);
  if (f == nullptr || t == nullptr || f->quantity != t->quantity) return std::nullopt;
  // si = x f.factor + f.offset; y = (si - t.offset) / t.factor
  return LinearConversion{f->factor / t->factor, (f->offset - t->offset) / t->factor};
}

}  // namespace dynid::car
