#pragma once
// The reference simulator: integrates a scenario with fixed-step RK4 at the internal rate,
// samples every channel when its CAN message is due (sensor rate), adds the sensor errors,
// quantizes through the DBC, writes the frames, and records the channels on the output grid.
//
// Contract: simulate() is deterministic in (scenario, seed, DBC). On the output grid
// (t_k = k / output_rate, k = 0 .. duration * output_rate) `truth` holds the true values at t_k
// and `measured` holds, per channel, the last sensor sample taken at or before t_k (what a
// receiver resampling the bus by zero-order hold sees); channels no message carries are sampled
// on the output grid. Measured values equal what the CAN frames decode to, exactly, for every
// channel a message carries (when quantization is off the CSV keeps full precision while the
// frames still quantize).
// Clutch: a stick/slip state machine between steps. A slipping clutch locks when the slip
// speed crosses zero and the stuck clutch could carry the torque; a locked clutch slips when the
// torque it must carry exceeds mu_static R_eq F_n.
#include <cstdint>
#include <vector>

#include <dynid/can/dbc.hpp>
#include <dynid/can/frame.hpp>

#include "dynid/sim/channels.hpp"
#include "dynid/sim/scenario.hpp"

namespace dynid::sim {

struct RunStatistics {
  int clutch_locks = 0;
  int clutch_unlocks = 0;
  double slipping_time = 0.0;     // s with the clutch slipping under a clamp load
  double max_lateral_slip = 0.0;  // largest |ay| seen, m/s^2 (true)
};

struct Run {
  Scenario scenario;
  std::uint64_t seed = 0;
  std::vector<ChannelInfo> channels;
  std::vector<double> time;                   // output grid, s from the start
  std::vector<std::vector<double>> truth;     // [sample][channel]
  std::vector<std::vector<double>> measured;  // [sample][channel]
  std::vector<double> offsets;                // per channel, as applied
  std::vector<can::Frame> frames;
  RunStatistics statistics;
};

Run simulate(const Scenario& scenario, std::uint64_t seed, const can::Database& dbc);

// One RK4 step of length h with inputs and mode held.
State rk4_step(const CarModel& model, const State& s, const DriverInputs& in, const Mode& mode, double h);

}  // namespace dynid::sim
