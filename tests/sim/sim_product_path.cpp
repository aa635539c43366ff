#include "sim_product_path.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <unistd.h>

#include <dynid/car/candump_source.hpp>
#include <dynid/car/pipeline.hpp>
#include <dynid/car/replay.hpp>

#include "dynid/sim/outputs.hpp"
#include "sim_test_support.hpp"

namespace dynid::sim::test {

const car::VehicleProfile& testcar_profile() {
  static const car::VehicleProfile p = car::load_vehicle_profile(DYNID_TESTCAR_PROFILE);
  return p;
}

ingest::ModelSpec model_spec(const std::string& name, std::vector<std::string> effects,
                             const model::Constants& extra) {
  for (const auto& m : testcar_profile().models)
    if (m.model == name) {
      ingest::ModelSpec s = m;
      s.effects = std::move(effects);
      for (const auto& [k, v] : extra) s.constants[k] = v;
      return s;
    }
  ADD_FAILURE() << "the test car's profile has no model " << name;
  return {};
}

void replay_run(const Run& r, const std::string& run_name, const std::function<void(ingest::Chunk&&)>& sink) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("dynid-simpath-" + std::to_string(::getpid()) + "-" + run_name);
  std::filesystem::create_directories(dir);
  write_can_log(dir / "can.log", r);
  car::CarPipeline pipeline(testcar_profile(), run_name, sink);
  car::CandumpSource source(dir / "can.log");
  const car::ReplayProgress progress = car::replay(source, pipeline);
  std::filesystem::remove_all(dir);
  EXPECT_EQ(progress.bad, 0U) << run_name;
  EXPECT_EQ(progress.unknown_id, 0U) << run_name;
  EXPECT_GT(progress.rows, 0U) << run_name;
}

std::vector<ingest::Chunk> replay_chunks(const Run& r, const std::string& run_name) {
  std::vector<ingest::Chunk> chunks;
  replay_run(r, run_name, [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
  return chunks;
}

ingest::ZeroCalibration tare_for(const Run& r, const std::string& tare_scenario_text) {
  const Run tare = test::run(tare_scenario_text, r.seed);
  const std::string name = "tare-" + r.scenario.name + "-" + std::to_string(r.seed);
  ingest::ZeroCalibration zero(testcar_profile().announcement(name), {"wheel_torque", "clutch_clamp_load"});
  replay_run(tare, name, [&](ingest::Chunk&& c) { zero.push(c); });
  if (std::getenv("DYNID_ACCURACY_VERBOSE") != nullptr)
    for (const auto& [channel, value] : zero.zeros())
      std::printf("tare %s: zero %.4g, simulated offset %.4g\n", channel.c_str(), value,
                  r.offsets[channel_index(channel)]);
  return zero;
}

}  // namespace dynid::sim::test
