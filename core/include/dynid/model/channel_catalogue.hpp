#pragma once
// The channel catalogue of docs/CHANNELS.md as code, the one copy: the names a vehicle profile may
// map signals onto, the simulator writes and the models read, and the SI unit string each must
// carry (models check those strings exactly).
//
// Contract: channel_unit() returns the unit of a catalogue channel, including the measured
// derivative channels d_<name> (unit of <name> per second: "m/s" -> "m/s^2", "rad/s" ->
// "rad/s^2", "m" -> "m/s"), and nullopt for any other name.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::model {

std::optional<std::string> channel_unit(std::string_view channel);
/// Every base channel name (no d_ derivatives), in catalogue order.
const std::vector<std::string>& channel_names();

}  // namespace dynid::model
