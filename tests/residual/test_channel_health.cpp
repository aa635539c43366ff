// Channel health (ingest/channel_health.hpp) on simulated runs through the product's data path
// (the simulator's CAN log decoded with the test car's DBC and profile): every standard scenario,
// noisy and noise-free, has no finding; a run with one channel edited (constant, stuck for a
// span, the DBC's sentinel, out of its physical range, mostly invalid) has the finding, and the
// server's replies (estimate tables, excitation, trace, consistency) judge no model that reads
// the channel.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

#include <dynid/car/candump_source.hpp>
#include <dynid/car/pipeline.hpp>
#include <dynid/car/replay.hpp>
#include <dynid/car/vehicle_profile.hpp>

#include "car_test_support.hpp"
#include "dynid/ingest/channel_health.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/report/excitation_report.hpp"
#include "dynid/server/estimate_tables.hpp"
#include "dynid/server/residual_requests.hpp"
#include "sim_product_path.hpp"
#include "sim_test_support.hpp"

namespace dynid::ingest {
namespace {

struct ReplayedRun {
  RunAnnouncement announcement;
  std::vector<Chunk> chunks;
};

ReplayedRun replayed(const std::string& scenario_text, const std::string& name,
                     std::uint64_t seed = 1) {
  const sim::Run run = sim::test::run(scenario_text, seed);
  return {sim::test::testcar_profile().announcement(name), sim::test::replay_chunks(run, name)};
}

RunHealth health_of(const ReplayedRun& run) {
  return channel_health(assemble_run(run.announcement, run.chunks));
}

std::string statements(const RunHealth& health) {
  std::string out;
  for (const ChannelFinding& f : health.findings) out += "  " + f.statement + "\n";
  return out;
}

// The committed scenarios as they are (sensor noise and offsets), and noise-free: a car that
// drives straight, stands or holds a steady state holds its channels exactly there, which is
// not a fault.
TEST(ChannelHealth, TheStandardScenariosHaveNoFindingNoisyOrNoiseFree) {
  for (const auto& entry : std::filesystem::directory_iterator(DYNID_SCENARIO_DIR)) {
    const std::string file = entry.path().filename().string();
    const std::string text = sim::test::load_scenario_text(file);
    for (const bool noisy : {true, false}) {
      const std::string scenario =
          noisy ? text : text + "\n[effects]\nsensor_noise = false\nsensor_offsets = false\n";
      const ReplayedRun run = replayed(scenario, noisy ? "noisy" : "quiet");
      const RunHealth health = health_of(run);
      EXPECT_EQ(health.channels, run.announcement.channels.size());
      EXPECT_TRUE(health.findings.empty())
          << file << (noisy ? " (noisy)" : " (noise-free)") << ":\n"
          << statements(health);
    }
  }
}

// The comma2k19 RAV4 log (real data: a production car's CAN bus, deploy/profiles/rav4.toml)
// replayed through the car-side path, as dynid-car --replay does.
ReplayedRun replayed_rav4() {
  const car::VehicleProfile profile =
      car::load_vehicle_profile(car::test::profile_path("rav4.toml"));
  ReplayedRun run{profile.announcement("seg40"), {}};
  car::CarPipeline pipeline(profile, "seg40",
                            [&](Chunk&& c) { run.chunks.push_back(std::move(c)); });
  car::CandumpSource source(car::test::rav4_log());
  (void)car::replay(source, pipeline);
  return run;
}

// One channel of every chunk edited: `edit(value, time)` gives the new value; rows stay valid.
void edit_channel(ReplayedRun& run, const std::string& channel,
                  const std::function<double(double value, double time_s)>& edit) {
  const auto column = static_cast<Eigen::Index>(run.announcement.column_of(channel));
  for (Chunk& chunk : run.chunks) {
    for (Eigen::Index i = 0; i < chunk.samples.rows(); ++i) {
      const double t =
          static_cast<double>(chunk.first_sample_index + static_cast<std::uint64_t>(i)) /
          run.announcement.sample_rate_hz;
      chunk.samples(i, column) = edit(chunk.samples(i, column), t);
    }
    chunk.seal();
  }
}

// The acceleration run (30 s, upshifts, varying throttle) with the models that read the edited
// channels: kinematic_longitudinal (ax, vx), longitudinal_wheel (wheel_torque, vx) and
// lateral_bicycle, which reads neither ax nor wheel_torque.
ReplayedRun acceleration_run() {
  ReplayedRun run =
      replayed(sim::test::load_scenario_text("acceleration.toml"), "acceleration-edited", 5);
  run.announcement.models = {sim::test::model_spec("kinematic_longitudinal", {}),
                             sim::test::model_spec("longitudinal_wheel", {"road_grade"}),
                             sim::test::model_spec("lateral_bicycle", {})};
  return run;
}

const ChannelFinding& only_finding(const RunHealth& health) {
  static const ChannelFinding none{};
  EXPECT_EQ(health.findings.size(), 1u) << statements(health);
  return health.findings.empty() ? none : health.findings.front();
}

bool reads_unhealthy(const ReplayedRun& run, const RunHealth& health, const std::string& model) {
  for (const ModelSpec& spec : run.announcement.models)
    if (spec.model == model)
      return unhealthy_reason(health, run.announcement,
                              *model::make_model(spec.model, spec.constants), spec.effects)
          .has_value();
  ADD_FAILURE() << "no model " << model;
  return false;
}

// A real log: no finding as recorded; its ax edited to a constant is found and blocks the
// kinematic model, as on the simulated run.
TEST(ChannelHealth, TheRav4LogHasNoFindingAndItsStuckAccelerometerIsFound) {
  DYNID_REQUIRE_RAV4_DATA();
  ReplayedRun run = replayed_rav4();
  const RunHealth recorded = health_of(run);
  EXPECT_TRUE(recorded.findings.empty()) << statements(recorded);
  edit_channel(run, "ax", [](double, double) { return -0.57; });
  const RunHealth stuck = health_of(run);
  const ChannelFinding& f = only_finding(stuck);
  EXPECT_EQ(f.kind, HealthFinding::kConstant);
  EXPECT_NE(f.statement.find("`ax` is constant at -0.57 m/s^2"), std::string::npos) << f.statement;
  EXPECT_TRUE(reads_unhealthy(run, stuck, "kinematic_longitudinal"));
}

TEST(ChannelHealth, AnAccelerometerConstantForTheWholeRunIsFound) {
  ReplayedRun run = acceleration_run();
  edit_channel(run, "ax", [](double, double) { return -0.57; });
  const RunHealth health = health_of(run);
  const ChannelFinding& f = only_finding(health);
  EXPECT_EQ(f.kind, HealthFinding::kConstant);
  EXPECT_EQ(f.channel, "ax");
  EXPECT_DOUBLE_EQ(f.value, -0.57);
  EXPECT_DOUBLE_EQ(f.share, 1.0);
  EXPECT_NE(f.statement.find("`ax` is constant at -0.57 m/s^2 from "), std::string::npos)
      << f.statement;
  EXPECT_NE(f.statement.find("(100 % of its valid samples)"), std::string::npos) << f.statement;
  EXPECT_TRUE(reads_unhealthy(run, health, "kinematic_longitudinal"));
  // Its optional ax serves an accelerometer effect the profile does not enable.
  EXPECT_FALSE(reads_unhealthy(run, health, "longitudinal_wheel"));
  EXPECT_FALSE(reads_unhealthy(run, health, "lateral_bicycle"));
}

TEST(ChannelHealth, AnAccelerometerStuckForASpanIsFoundWithTheSpan) {
  ReplayedRun run = acceleration_run();
  // From 6 s to 24 s (60 % of the 30 s run) ax keeps the value it had at 6 s.
  std::optional<double> held;
  edit_channel(run, "ax", [&](double x, double t) {
    if (t < 6.0 || t > 24.0) return x;
    if (!held) held = x;
    return *held;
  });
  const RunHealth health = health_of(run);
  const ChannelFinding& f = only_finding(health);
  EXPECT_EQ(f.kind, HealthFinding::kConstant);
  EXPECT_EQ(f.channel, "ax");
  EXPECT_NEAR(f.from_s, 6.0, 0.2);
  EXPECT_NEAR(f.to_s, 24.0, 0.2);
  EXPECT_NEAR(f.share, 0.6, 0.02);
  EXPECT_TRUE(reads_unhealthy(run, health, "kinematic_longitudinal"));
}

TEST(ChannelHealth, TheDbcSentinelInTheWheelTorqueIsCalledAnInvalidMarker) {
  ReplayedRun run = acceleration_run();
  edit_channel(run, "wheel_torque", [](double, double) { return -131072.0; });
  const RunHealth health = health_of(run);
  const ChannelFinding& f = only_finding(health);
  EXPECT_EQ(f.kind, HealthFinding::kSentinel);
  EXPECT_EQ(f.channel, "wheel_torque");
  EXPECT_NE(
      f.statement.find(
          "`wheel_torque` reads -1.31e+05 N m, outside its physical range [-3e+04, 3e+04] N m"),
      std::string::npos)
      << f.statement;
  EXPECT_NE(f.statement.find("an invalid marker"), std::string::npos) << f.statement;
  EXPECT_TRUE(reads_unhealthy(run, health, "longitudinal_wheel"));
  EXPECT_FALSE(reads_unhealthy(run, health, "kinematic_longitudinal"));
}

TEST(ChannelHealth, ASpeedOutOfItsPhysicalRangeIsFoundWithItsExtreme) {
  ReplayedRun run = acceleration_run();
  // A decoding fault: 3 s of vx at 50 times its value (well above 120 m/s), each sample different.
  edit_channel(run, "vx", [](double x, double t) { return t >= 10.0 && t < 13.0 ? 50.0 * x : x; });
  const RunHealth health = health_of(run);
  const ChannelFinding& f = only_finding(health);
  EXPECT_EQ(f.kind, HealthFinding::kOutOfRange);
  EXPECT_EQ(f.channel, "vx");
  EXPECT_GT(f.value, 120.0);
  EXPECT_NEAR(f.from_s, 10.0, 0.1);
  EXPECT_NEAR(f.to_s, 13.0, 0.1);
  EXPECT_NE(
      f.statement.find("`vx` is outside its physical range [-120, 120] m/s from 10 s to 13 s"),
      std::string::npos)
      << f.statement;
  // Every model here reads vx (kinematic_longitudinal through d_vx).
  for (const char* model : {"kinematic_longitudinal", "longitudinal_wheel", "lateral_bicycle"})
    EXPECT_TRUE(reads_unhealthy(run, health, model)) << model;
}

// The `p` quantile of |value| over the valid samples of `channel` (1: the largest).
double quantile_of_magnitude(const ReplayedRun& run, const std::string& channel, double p) {
  const auto column = static_cast<Eigen::Index>(run.announcement.column_of(channel));
  std::vector<double> values;
  for (const Chunk& chunk : run.chunks)
    for (Eigen::Index i = 0; i < chunk.samples.rows(); ++i)
      if (chunk.valid[static_cast<std::size_t>(i)] != 0)
        values.push_back(std::abs(chunk.samples(i, column)));
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(p * static_cast<double>(values.size() - 1))];
}

// A real log's longitudinal accelerometer with a range of half what the car reached (its
// accelerations and brakings pass it 25 times): its peaks are cut flat, and the finding says so;
// unedited, the same log has no finding (above).
TEST(ChannelHealth, TheRav4LogsAccelerometerClippedByItsRangeIsFound) {
  DYNID_REQUIRE_RAV4_DATA();
  ReplayedRun run = replayed_rav4();
  const double range = 0.5 * quantile_of_magnitude(run, "ax", 1.0);
  edit_channel(run, "ax", [&](double x, double) { return std::clamp(x, -range, range); });
  const RunHealth health = health_of(run);
  const ChannelFinding& f = only_finding(health);
  EXPECT_EQ(f.kind, HealthFinding::kClipped);
  EXPECT_EQ(f.channel, "ax");
  EXPECT_NEAR(std::abs(f.value), range, 1e-9);
  EXPECT_NE(f.statement.find("`ax` clips at "), std::string::npos) << f.statement;
  EXPECT_NE(f.statement.find("the sensor's range, not the car's motion"), std::string::npos)
      << f.statement;
  std::printf("%s\n", f.statement.c_str());
}

// The simulated acceleration run's longitudinal accelerometer with a range of 70 % of its
// largest value: found, and the model that reads it is not judged; the others are.
TEST(ChannelHealth, AClippedAccelerometerBlocksTheModelThatReadsIt) {
  ReplayedRun run = acceleration_run();
  const double range = 0.7 * quantile_of_magnitude(run, "ax", 1.0);
  edit_channel(run, "ax", [&](double x, double) { return std::clamp(x, -range, range); });
  const RunHealth health = health_of(run);
  const ChannelFinding& f = only_finding(health);
  EXPECT_EQ(f.kind, HealthFinding::kClipped);
  EXPECT_EQ(f.channel, "ax");
  EXPECT_GT(f.share, 0.0);
  EXPECT_TRUE(reads_unhealthy(run, health, "kinematic_longitudinal"));
  EXPECT_FALSE(reads_unhealthy(run, health, "lateral_bicycle"));
}

TEST(ChannelHealth, AMostlyInvalidRunIsReportedButBlocksNoModel) {
  ReplayedRun run = acceleration_run();
  const auto rate = run.announcement.sample_rate_hz;
  for (Chunk& chunk : run.chunks) {  // invalid but for 0..8 s: 73 % of the run
    for (Eigen::Index i = 0; i < chunk.samples.rows(); ++i)
      if (static_cast<double>(chunk.first_sample_index + static_cast<std::uint64_t>(i)) / rate >
          8.0)
        chunk.valid[static_cast<std::size_t>(i)] = 0;
    chunk.seal();
  }
  const RunHealth health = health_of(run);
  const ChannelFinding& f = only_finding(health);
  EXPECT_EQ(f.kind, HealthFinding::kMostlyInvalid);
  EXPECT_FALSE(f.blocks_models());
  EXPECT_NEAR(f.share, 0.73, 0.01);
  EXPECT_EQ(f.statement.rfind("73.9 % of the run's samples from 0 s to 29.9 s are invalid", 0), 0u)
      << f.statement;
  EXPECT_FALSE(reads_unhealthy(run, health, "kinematic_longitudinal"));
}

// The server's replies for the run with ax constant: the model that reads it is not judged
// anywhere (tables, excitation, trace, consistency); the others keep their tables.
struct Replies {
  nlohmann::json tables;
  std::string tables_text, excitation_text, trace_text;
  nlohmann::json consistency;
};

Replies replies_of(const ReplayedRun& run) {
  RunProcessor processor(run.announcement);
  for (const Chunk& chunk : run.chunks) processor.push(chunk);
  processor.finish();
  const RunHealth health = health_of(run);
  server::EstimateTables tables =
      server::tables_of(run.announcement.vehicle, run.announcement.run, processor.estimates());
  server::apply_health(tables, health, run.announcement);
  Replies out{nlohmann::json::parse(server::render(tables, true)),
              server::render(tables, false),
              {},
              {},
              {}};
  out.excitation_text = report::format_excitation_text(
      server::excitation_of(run.announcement.vehicle, run.announcement.run, processor.estimates(),
                            health, run.announcement));
  server::ResidualRequest trace;
  trace.kind = "trace";
  trace.model = "kinematic_longitudinal";
  trace.format = "text";
  out.trace_text = server::residual_reply(run.announcement, run.chunks, trace).payload;
  server::ResidualRequest consistency;
  consistency.kind = "consistency";
  consistency.format = "json";
  out.consistency = nlohmann::json::parse(
      server::residual_reply(run.announcement, run.chunks, consistency).payload);
  return out;
}

const nlohmann::json& table_of(const nlohmann::json& tables, const std::string& model) {
  for (const auto& t : tables.at("tables"))
    if (t.at("model") == model) return t;
  throw std::runtime_error("no table of " + model);
}

TEST(ChannelHealth, TheRepliesJudgeNoModelThatReadsAConstantAccelerometer) {
  ReplayedRun run = acceleration_run();
  edit_channel(run, "ax", [](double, double) { return -0.57; });
  const Replies r = replies_of(run);
  const nlohmann::json& kinematic = table_of(r.tables, "kinematic_longitudinal");
  EXPECT_NE(
      kinematic.at("not_identified").get<std::string>().find("`ax` is constant at -0.57 m/s^2"),
      std::string::npos)
      << kinematic.dump();
  EXPECT_EQ(kinematic.at("not_excited"), "");
  EXPECT_EQ(kinematic.at("residual_verdict"), "");
  for (const auto& p : kinematic.at("parameters")) {
    EXPECT_EQ(p.at("status"), "not identified") << p.dump();
    EXPECT_EQ(p.at("reason"), kinematic.at("not_identified")) << p.dump();
  }
  // The models that do not read ax are judged as before.
  int judged = 0;
  for (const auto& t : r.tables.at("tables"))
    if (t.at("model") != "kinematic_longitudinal") {
      EXPECT_EQ(t.at("not_identified"), "") << t.dump();
      ++judged;
    }
  EXPECT_GT(judged, 0) << r.tables_text;
  // Text: the table is one line, no status, no advice.
  const auto block = r.tables_text.find("/ kinematic_longitudinal");
  ASSERT_NE(block, std::string::npos) << r.tables_text;
  const std::string kinematic_text =
      r.tables_text.substr(block, r.tables_text.find("\n\n", block) - block);
  std::printf("estimates:\n%s\n\nexcitation:\n%s\ntrace:\n%s", kinematic_text.c_str(),
              r.excitation_text.c_str(), r.trace_text.c_str());
  EXPECT_NE(kinematic_text.find("not identified: `ax` is constant at -0.57 m/s^2"),
            std::string::npos)
      << kinematic_text;
  for (const char* word : {"poorly", " identified ", "needs", "adequate", "not excited"})
    EXPECT_EQ(kinematic_text.find(word), std::string::npos) << word << " in\n" << kinematic_text;
  // Excitation: the one line, and no manoeuvre advised for its parameters.
  EXPECT_NE(r.excitation_text.find("kinematic_longitudinal: not identified: `ax` is constant"),
            std::string::npos)
      << r.excitation_text;
  EXPECT_EQ(r.excitation_text.find("kinematic_longitudinal."), std::string::npos)
      << r.excitation_text;
  // Trace: one line instead of a diagnosis.
  EXPECT_NE(
      r.trace_text.find("kinematic_longitudinal: not identified: `ax` is constant at -0.57 m/s^2"),
      std::string::npos)
      << r.trace_text;
  EXPECT_EQ(r.trace_text.find("adequate"), std::string::npos) << r.trace_text;
  // Consistency: left out, with the reason.
  const std::string left_out = r.consistency.at("left_out").dump();
  EXPECT_NE(left_out.find("kinematic_longitudinal: not identified: `ax` is constant"),
            std::string::npos)
      << r.consistency.dump();
}

TEST(ChannelHealth, TheRepliesJudgeNoModelThatReadsASentinelTorque) {
  ReplayedRun run = acceleration_run();
  edit_channel(run, "wheel_torque", [](double, double) { return -131072.0; });
  const Replies r = replies_of(run);
  const nlohmann::json& wheel = table_of(r.tables, "longitudinal_wheel");
  EXPECT_NE(wheel.at("not_identified").get<std::string>().find("an invalid marker"),
            std::string::npos)
      << wheel.dump();
  for (const auto& p : wheel.at("parameters"))
    EXPECT_EQ(p.at("status"), "not identified") << p.dump();
  EXPECT_EQ(table_of(r.tables, "kinematic_longitudinal").at("not_identified"), "");
  EXPECT_NE(r.excitation_text.find(
                "longitudinal_wheel: not identified: `wheel_torque` reads -1.31e+05 N m"),
            std::string::npos)
      << r.excitation_text;
  EXPECT_EQ(r.excitation_text.find("longitudinal_wheel."), std::string::npos) << r.excitation_text;
  EXPECT_NE(r.consistency.at("left_out").dump().find("longitudinal_wheel: not identified"),
            std::string::npos)
      << r.consistency.dump();
}

}  // namespace
}  // namespace dynid::ingest
