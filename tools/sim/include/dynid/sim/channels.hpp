#pragma once
// The channels the simulator writes, named and in the SI units of docs/CHANNELS.md, and their
// true (noise-free) values computed from the car's state.
//
// Contract: channel_catalogue() lists every channel once, in CSV column order. True values:
// the accelerometer gives the specific force (acceleration minus gravity) at the IMU point in
// body axes (so it sees gravity through roll, pitch, grade and bank, as a real one does); gyros
// give body rates; `vx` is the mean of the four wheel circumferential speeds; `vy` the lateral
// speed at the CG in the yaw frame; hub forces are the tyre contact forces in the yaw frame
// (the rim mass and the hub moments are not modelled); susp_force is the spring-damper-bar force
// on the body, static part included; `roll` is the body's roll angle to the road from the
// suspension travels and tyre deflections (what ride-height lasers on the body measure).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/sim/car_model.hpp"

namespace dynid::sim {

struct ChannelInfo {
  std::string name;
  std::string unit;
};

const std::vector<ChannelInfo>& channel_catalogue();
// Index in channel_catalogue(); throws InputError for a name it does not hold.
std::size_t channel_index(std::string_view name);

std::vector<double> true_channel_values(const CarModel& model, const State& state,
                                        const DriverInputs& inputs, const Evaluation& evaluation);

}  // namespace dynid::sim
