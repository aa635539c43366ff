// The dynid-car program against the test-side acknowledger over loopback DDS: a replayed
// simulated run arrives complete and bit for bit as the car's own pipeline cuts it; a car that
// found no server exits non-zero, keeps everything, and a restart delivers it in order; a full
// spool stops the reading with a clear message.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "client_fixture.hpp"
#include "dynid/car/chunk_file.hpp"
#include "dynid/error.hpp"
#include "dynid/car/spool.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {
namespace {

using namespace testing;

std::vector<std::string> car_args(const ScratchDir& scratch, const std::string& run) {
  return {DYNID_CAR, "--profile", testcar_profile().string(), "--cyclone-config", loopback_options().config,
          "--domain", std::to_string(kDomain), "--spool",
          (scratch.path() / "spool").string(), "--run", run};
}

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

// Polls the acker while the car runs; returns the car's exit status.
std::optional<int> serve_until_exit(Child& car, TestAcker* acker, std::chrono::milliseconds patience = 60s) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  while (car.running() && std::chrono::steady_clock::now() < deadline) {
    if (acker) acker->poll(20ms);
    else std::this_thread::sleep_for(20ms);
  }
  return car.wait(1s);
}

TEST(ClientProgram, AReplayedRunArrivesCompleteAndBitForBit) {
  ScratchDir scratch("program-replay");
  const auto run_dir = simulated_run("step_steer", scratch);
  const auto expected = expected_chunks(run_dir / "can.log", "replay-1");
  ASSERT_GT(expected.size(), 5U);

  dds::Participant server(loopback_options());
  TestAcker acker(server, "dynid-testcar");
  const auto log = scratch.path() / "car.log";
  Child car(with(car_args(scratch, "replay-1"), {"--replay", (run_dir / "can.log").string(), "--fast",
                                                 "--drain-timeout", "20"}),
            log);
  EXPECT_EQ(serve_until_exit(car, &acker), 0) << read_text(log);
  const std::string out = read_text(log);

  ASSERT_EQ(acker.distinct("replay-1"), expected.size()) << out;
  for (const auto& c : acker.received) EXPECT_TRUE(same_chunk(c, expected.at(c.sequence))) << c.sequence;
  ASSERT_FALSE(acker.announcements.empty());
  EXPECT_EQ(static_cast<Eigen::Index>(acker.announcements.front().channels.size()), expected.front().samples.cols());
  EXPECT_NE(out.find("all chunks acknowledged"), std::string::npos) << out;
  EXPECT_NE(out.find("% of can.log"), std::string::npos) << "progress lines: " << out;
  Spool spool(scratch.path() / "spool", 1 << 20);
  EXPECT_EQ(spool.count(), 0U);
}

TEST(ClientProgram, NoServerMeansExitTwoAndARestartDeliversEverythingInOrder) {
  ScratchDir scratch("program-restart");
  const auto run_dir = simulated_run("step_steer", scratch);
  const auto expected = expected_chunks(run_dir / "can.log", "offline-1");
  const auto log = scratch.path() / "car.log";
  {
    Child car(with(car_args(scratch, "offline-1"),
                   {"--replay", (run_dir / "can.log").string(), "--fast", "--drain-timeout", "1"}),
              log);
    EXPECT_EQ(serve_until_exit(car, nullptr), 2) << read_text(log);
  }
  const std::string first = read_text(log);
  EXPECT_NE(first.find("not everything was acknowledged within 1 s"), std::string::npos) << first;
  EXPECT_NE(first.find("no server ever matched"), std::string::npos) << first;
  {
    Spool spool(scratch.path() / "spool", 1 << 30);
    EXPECT_EQ(spool.count(), expected.size()) << "everything kept for the next start";
  }
  {  // the same run id again is refused: it would mix two recordings under one sequence
    Child again(with(car_args(scratch, "offline-1"), {"--replay", (run_dir / "can.log").string(), "--fast"}),
                scratch.path() / "again.log");
    EXPECT_EQ(again.wait(30s), 1);
    EXPECT_NE(read_text(scratch.path() / "again.log").find("choose a new --run"), std::string::npos);
  }

  dds::Participant server(loopback_options());
  TestAcker acker(server, "dynid-testcar");
  auto args = car_args(scratch, "unused");
  args.resize(args.size() - 2);  // no --run, no source: deliver what the spool holds
  Child restarted(with(args, {"--drain-timeout", "20"}), scratch.path() / "restart.log");
  EXPECT_EQ(serve_until_exit(restarted, &acker), 0) << read_text(scratch.path() / "restart.log");
  ASSERT_EQ(acker.distinct("offline-1"), expected.size());
  // In order: the first copy of every chunk arrives in sequence order.
  std::vector<std::uint64_t> first_seen;
  for (const auto& c : acker.received)
    if (std::find(first_seen.begin(), first_seen.end(), c.sequence) == first_seen.end())
      first_seen.push_back(c.sequence);
  for (std::size_t i = 0; i < first_seen.size(); ++i) EXPECT_EQ(first_seen[i], i);
  for (const auto& c : acker.received) EXPECT_TRUE(same_chunk(c, expected.at(c.sequence)));
  ASSERT_FALSE(acker.announcements.empty()) << "the restarted car announced the pending run again";
  EXPECT_EQ(acker.announcements.front().run, "offline-1");
}

TEST(ClientProgram, AFullSpoolStopsReadingWithAClearMessage) {
  ScratchDir scratch("program-full");
  const auto run_dir = simulated_run("step_steer", scratch);
  // The test car's profile with a spool of three and a half chunks.
  const auto expected = expected_chunks(run_dir / "can.log", "full-1");
  const std::uint64_t max_bytes = ingest::encode_chunk(expected.front()).size() * 7 / 2;
  std::string text = read_text(testcar_profile());
  text = std::regex_replace(text, std::regex(R"(dbc = "[^"]*")"),
                            "dbc = \"" + (source_dir() / "deploy" / "dbc" / "dynid_testcar.dbc").string() + "\"");
  text = std::regex_replace(text, std::regex(R"(max_bytes = \d+)"), "max_bytes = " + std::to_string(max_bytes));
  const auto profile = scratch.path() / "small-spool.toml";
  { std::ofstream(profile) << text; }
  ASSERT_EQ(load_vehicle_profile(profile).spool_max_bytes, max_bytes);

  auto args = car_args(scratch, "full-1");
  args[2] = profile.string();
  const auto log = scratch.path() / "car.log";
  Child car(with(args, {"--replay", (run_dir / "can.log").string(), "--fast", "--drain-timeout", "1"}), log);
  EXPECT_EQ(serve_until_exit(car, nullptr), 3) << read_text(log);
  const std::string out = read_text(log);
  EXPECT_NE(out.find("spool full: "), std::string::npos) << out;
  EXPECT_NE(out.find("stopped reading"), std::string::npos) << out;
  Spool spool(scratch.path() / "spool", max_bytes);
  const auto pending = spool.pending_entries();
  ASSERT_EQ(pending.size(), 3U) << "what fitted is kept";
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(pending[i].sequence, i);
}

// --chunks-out: no server and no DDS configuration; the file holds exactly the chunks the
// pipeline cuts from the log, in order, and a cut-off file is refused rather than half read.
TEST(ClientProgram, ChunksOutWritesTheRunsChunksWithoutAServer) {
  ScratchDir scratch("program-chunks-out");
  const auto run_dir = simulated_run("step_steer", scratch);
  const auto expected = expected_chunks(run_dir / "can.log", "file-1");
  ASSERT_GT(expected.size(), 5U);
  const auto file = scratch.path() / "run.chunks";
  const auto log = scratch.path() / "car.log";
  Child car({DYNID_CAR, "--profile", testcar_profile().string(), "--run", "file-1", "--replay",
             (run_dir / "can.log").string(), "--fast", "--chunks-out", file.string()},
            log);
  EXPECT_EQ(serve_until_exit(car, nullptr), 0) << read_text(log);
  const auto written = read_chunk_file(file);
  ASSERT_EQ(written.size(), expected.size()) << read_text(log);
  for (std::size_t i = 0; i < written.size(); ++i) EXPECT_TRUE(same_chunk(written[i], expected[i])) << i;
  EXPECT_NE(read_text(log).find(std::to_string(expected.size()) + " chunks ("), std::string::npos) << read_text(log);

  const std::string bytes = read_text(file);
  { std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() - 3); }
  EXPECT_THROW(read_chunk_file(file), InputError);
}

TEST(ClientProgram, ChunksOutNeedsASourceAndOtherwiseACycloneConfig) {
  ScratchDir scratch("program-chunks-args");
  const auto log = scratch.path() / "car.log";
  Child bare({DYNID_CAR, "--profile", testcar_profile().string(), "--chunks-out",
              (scratch.path() / "x.chunks").string()},
             log);
  EXPECT_EQ(serve_until_exit(bare, nullptr), 1);
  EXPECT_NE(read_text(log).find("needs --replay or --can"), std::string::npos) << read_text(log);
  Child no_config({DYNID_CAR, "--profile", testcar_profile().string()}, log);
  EXPECT_EQ(serve_until_exit(no_config, nullptr), 1);
  EXPECT_NE(read_text(log).find("--cyclone-config is required"), std::string::npos) << read_text(log);
}

}  // namespace
}  // namespace dynid::car
