#pragma once
// Unit conversion where signals enter: from a DBC signal's unit string to a channel's SI unit.
//
// The table knows the spellings real DBC files use for the quantities of the channel catalogue:
// speed (km/h, kph, mph, m/s), angle (deg, rad), angular rate (deg/s, rpm, rad/s), acceleration
// (m/s^2, m/s2, g), length (mm, cm, m), force (N, kN), torque (Nm, N m, N.m, kNm), pressure (Pa,
// kPa, bar, mbar, psi), ratio (%, "-"). A conversion is only between two units of the same
// quantity, so 'km/h' never silently becomes 'rad/s'.
//
// Contract: conversion() returns {factor, offset} with si = dbc * factor + offset, or nullopt
// when either unit is unknown or they measure different quantities. The empty DBC unit is not
// in the table (the profile decides what to do with it).
#include <optional>
#include <string_view>

namespace dynid::car {

struct LinearConversion {
  double factor = 1.0;
  double offset = 0.0;
  double apply(double x) const { return x * factor + offset; }
};

std::optional<LinearConversion> conversion(std::string_view from, std::string_view to);
/// True when the table knows this spelling.
bool known_unit(std::string_view unit);

}  // namespace dynid::car
