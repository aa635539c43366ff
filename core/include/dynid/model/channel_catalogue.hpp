#pragma once
// The channel catalogue of docs/CHANNELS.md as code, the one copy: the names a vehicle profile may
// map signals onto, the simulator writes and the models read, and the SI unit string each must
// carry (models check those strings exactly).
//
// Contract: channel_unit() returns the unit of a catalogue channel, including the measured
// derivative channels d_<name> (unit of <name> per second: "m/s" -> "m/s^2", "rad/s" ->
// "rad/s^2", "m" -> "m/s"), and nullopt for any other name. channel_physics() returns the values a
// base channel can physically take (docs/CHANNELS.md, "Physical ranges"): a sample outside is a
// decoding or sensor fault, which the run's channel health reports (ingest/channel_health.hpp).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::model {

std::optional<std::string> channel_unit(std::string_view channel);

/// What a base channel can physically be (docs/CHANNELS.md, "Physical ranges").
struct ChannelPhysics {
  double lower = 0.0;  ///< the closed range [lower, upper], SI
  double upper = 0.0;
  /// The value a car at rest or driving straight on a flat road holds exactly (0; g for `az`).
  double rest = 0.0;
  /// True where every steady state of a car (standing, a cruise, steady cornering) puts the
  /// channel at its rest value: `ax` (but on a grade), `az`, the roll and pitch rates. Held
  /// anywhere else, such a channel is stuck. Every other channel holds some value in a steady
  /// state (a speed, a steer, a static load, idle), so a held span is no fault of its own.
  bool holds_only_at_rest = false;
  /// True for the inertial sensors (the accelerometer's three axes, the three rates): a car's
  /// motion never stops one of them at a flat ceiling it enters and leaves steeply (there is no
  /// end stop, limiter or saturating actuator behind them, unlike a steer at full lock, an engine
  /// at its rev limit or a closed clutch), so such a ceiling is the sensor's range: clipping.
  bool inertial = false;
};
/// The physics of a base catalogue channel; nullopt for d_<name> and unknown names.
std::optional<ChannelPhysics> channel_physics(std::string_view channel);
const std::vector<std::string>& channel_names();

}  // namespace dynid::model
