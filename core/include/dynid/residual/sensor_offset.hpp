#pragma once
// Sensor offsets: a channel that reads a constant too much (issue 15: "sensor mounting: offset
// and misalignment against gravity"). An accelerometer tilted on its mount by a small angle reads
// g sin(angle) of gravity on its axis: pitched, ax; rolled, ay. A rate sensor's bias is the same
// kind of error. The effect `offset:<channel>@<value>` builds the model's rows on the channel
// minus `value` (in the channel's unit; its derivative d_<channel> is unchanged: an offset has
// none). It adds no column, like a located delay (signal_delay.hpp): the model's parameters are
// what they would be with the sensor read right.
//
// The screen (effect_screen.hpp) tests an offset of every accelerometer (unit m/s^2) and rate
// sensor (a catalogue name ending in "_rate", rad/s) the model reads, its measured side included:
// the column d r / d offset at the declared solution (central difference), tested like any added
// column; a significant offset is then found by Gauss-Newton (two steps from zero: exact for a
// model linear in the channel, as every model here is) and offered under its name, with its
// standard deviation and, for an accelerometer, the mounting angle it means.
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"

namespace dynid::residual {

struct SensorOffset {
  std::string channel;
  double value = 0.0;  ///< what the channel reads too much, in its unit
};

bool is_offset_effect(const std::string& name);

/// Parses offset:<channel>@<value>. InputError naming the effect when the form or the number is
/// wrong.
SensorOffset parse_offset_effect(const std::string& name);

/// The effect's name (the value with 6 significant digits).
std::string offset_effect_name(const std::string& channel, double value);

/// True for the channels whose offset the screen tests (see above), by name and unit; never a
/// derivative d_<x> (in m/s^2 when x is a speed, but made by the preprocessing, not measured).
bool is_mounted_sensor(const std::string& channel, const std::string& unit);

/// "ay reads +0.171 +- 0.010 m/s^2 too much: the accelerometer rolled +1.00 +- 0.06 deg on its
/// mount" (pitched for ax; the angle only for accelerometers, asin(value / g)).
std::string offset_finding(const std::string& channel, const std::string& unit, double value, double std);

/// The run with each offset channel read minus its offset. InputError when a channel is not in
/// the run.
std::vector<ingest::PreprocessedSegment> offset_corrected(const std::vector<ingest::PreprocessedSegment>& run,
                                                          const std::vector<SensorOffset>& offsets);

}  // namespace dynid::residual
