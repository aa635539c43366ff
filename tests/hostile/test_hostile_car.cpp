// dynid-car against hostile input (label hostile, car): CAN logs whose clock jumps forwards and
// backwards at every scale, files that are not CAN logs, inputs that are not regular files, every
// numeric option at and past its limits, vehicle ids and run names that could escape a path.
// Each: a clear message naming the input and the reason, exit 1 where the job cannot be done,
// bounded time (every child runs under a time limit), and nothing written (no chunk file).
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include <dynid/can/candump.hpp>
#include <dynid/car/chunk_file.hpp>
#include <dynid/car/vehicle_profile.hpp>

#include "hostile_support.hpp"

namespace dynid::hostile {
namespace {

constexpr double kEpoch = 1.7e9;  // logs carry epoch seconds
constexpr double kRate = 100.0;   // testcar.toml's grid

struct Replay {
  Outcome outcome;
  std::vector<ingest::Chunk> chunks;
  std::uint64_t rows = 0;
  std::uint64_t valid_rows = 0;
};

std::vector<can::Frame> at_epoch(std::vector<can::Frame> frames) {
  for (auto& f : frames) f.timestamp += kEpoch;
  return frames;
}

// dynid-car --chunks-out: the chunks a server would be sent, no server needed.
Replay replay(const std::vector<can::Frame>& frames, const ScratchDir& scratch,
              const std::vector<std::string>& pace = {"--fast"}, std::chrono::milliseconds limit = 20s) {
  const auto log = scratch.path() / "can.log";
  const auto out = scratch.path() / "run.chunks";
  write_log(log, frames);
  std::vector<std::string> args{"--profile", testcar_profile().string(), "--run", "r1", "--replay", log.string(),
                                "--chunks-out", out.string()};
  args.insert(args.end(), pace.begin(), pace.end());
  Replay r;
  r.outcome = run(Program::Car, args, scratch, limit);
  if (r.outcome.exit == 0) r.chunks = car::read_chunk_file(out);
  for (const auto& c : r.chunks)
    for (const auto v : c.valid) {
      ++r.rows;
      r.valid_rows += v;
    }
  return r;
}

const Replay& baseline() {
  static ScratchDir scratch("hostile-baseline");
  static const Replay r = replay(at_epoch(simulated_frames()), scratch);
  return r;
}

// Case 1 of issue 19: one frame 1e9 s ahead made the replay run until killed.
TEST(HostileCar, AFrameABillionSecondsAheadEndsInBoundedTime) {
  ASSERT_EQ(baseline().outcome.exit, 0) << describe(baseline().outcome);
  ScratchDir scratch("hostile-jump-1e9");
  auto frames = at_epoch(simulated_frames());
  frames[frames.size() / 2].timestamp += 1e9;
  const Replay r = replay(frames, scratch);
  ASSERT_EQ(r.outcome.exit, 0) << describe(r.outcome);
  EXPECT_LE(r.rows, baseline().rows + 3);
  EXPECT_LE(r.chunks.size(), baseline().chunks.size() + 1);
}

// The same jump paced on the log's clock: the jump is not waited for (5 s of log at 10x).
TEST(HostileCar, APacedReplayDoesNotWaitForAJump) {
  ScratchDir scratch("hostile-jump-paced");
  auto frames = at_epoch(simulated_frames("tare"));
  frames[frames.size() / 2].timestamp += 1e9;
  const Replay r = replay(frames, scratch, {"--speed", "10"}, 15s);
  ASSERT_EQ(r.outcome.exit, 0) << describe(r.outcome);
  EXPECT_LT(r.outcome.seconds, 5.0) << describe(r.outcome);
}

// Case 2 of issue 19: one frame 3 hours ahead made 10,820 chunks of nothing for 40 s of data.
TEST(HostileCar, AFrameThreeHoursAheadCutsNoChunkForTheGap) {
  ScratchDir scratch("hostile-jump-3h");
  auto frames = at_epoch(simulated_frames());
  frames[frames.size() / 3].timestamp += 3 * 3600.0;
  const Replay r = replay(frames, scratch);
  ASSERT_EQ(r.outcome.exit, 0) << describe(r.outcome);
  EXPECT_LE(r.chunks.size(), baseline().chunks.size() + 1) << describe(r.outcome);
  EXPECT_LE(r.rows, baseline().rows + 3);
  EXPECT_GE(r.valid_rows + 200, baseline().valid_rows) << "the data on both sides is kept";
}

// Every scale, forwards and backwards, one frame or the rest of the log: bounded rows (a jump
// longer than max_time_jump (10 s) costs nothing; a shorter one is a gap of invalid rows), the
// data on both sides kept, bounded time. Chunks are contiguous, each one a whole grid of rows.
TEST(HostileCar, ClockJumpsAtEveryScaleCostBoundedRowsAndKeepTheData) {
  ASSERT_EQ(baseline().outcome.exit, 0) << describe(baseline().outcome);
  ScratchDir scratch("hostile-jumps");
  for (const double scale : {1e-3, 0.05, 0.5, 5.0, 30.0, 3600.0, 1e6, 1e9})
    for (const double sign : {1.0, -1.0})
      for (const bool rest : {false, true}) {
        SCOPED_TRACE(std::to_string(sign * scale) + " s, " + (rest ? "from the middle on" : "one frame"));
        auto frames = at_epoch(simulated_frames());
        for (std::size_t i = frames.size() / 2; i < (rest ? frames.size() : frames.size() / 2 + 1); ++i)
          frames[i].timestamp += sign * scale;
        const Replay r = replay(frames, scratch);
        ASSERT_EQ(r.outcome.exit, 0) << describe(r.outcome);
        EXPECT_LT(r.outcome.seconds, 10.0);
        // Up to max_time_jump (10 s) a step is a gap of invalid rows (a frame 5 s back, then the
        // log again 5 s later: both steps are gaps); past it, a jump that costs no row.
        const double filled = scale <= 10.0 ? scale * kRate : 0.0;
        EXPECT_LE(static_cast<double>(r.rows), static_cast<double>(baseline().rows) + filled + 3);
        // Frames that go back less than the latency (1 s) are dropped until the log catches up.
        const double lost = sign < 0 && rest && scale < 1.0 ? scale * kRate : 0.0;
        EXPECT_GE(static_cast<double>(r.valid_rows) + lost + 200, static_cast<double>(baseline().valid_rows));
        for (std::size_t k = 1; k < r.chunks.size(); ++k)
          EXPECT_EQ(r.chunks[k].first_sample_index,
                    r.chunks[k - 1].first_sample_index + static_cast<std::uint64_t>(r.chunks[k - 1].samples.rows()));
      }
}

// A timestamp where a double no longer resolves a grid period (at 1e299 s, t + 0.01 == t) made the
// grid loop on one row, writing chunks until the disk was full; one at -1 s, or past 1e10 s
// (the year 2286), is dropped and counted, the rest of the log replayed as usual.
TEST(HostileCar, FramesAtAbsurdTimesAreDroppedAndCounted) {
  ScratchDir scratch("hostile-absurd-time");
  const auto frames = at_epoch(simulated_frames());
  std::ostringstream text;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    std::string line = can::format_candump_line(frames[i]);
    if (i == frames.size() / 3) line = "(" + std::string(300, '9') + line.substr(line.find('.'));
    if (i == frames.size() / 2) line = "(10000000001" + line.substr(line.find('.'));
    text << line << "\n";
  }
  const auto log = scratch.path() / "can.log";
  const auto out = scratch.path() / "run.chunks";
  write_text(log, text.str());
  const Outcome o = run(Program::Car, {"--profile", testcar_profile().string(), "--run", "r1", "--replay", log.string(),
                                       "--fast", "--chunks-out", out.string()},
                        scratch, 20s);
  ASSERT_EQ(o.exit, 0) << describe(o);
  EXPECT_NE(o.output.find("2 timestamps out of range"), std::string::npos) << describe(o);
  EXPECT_LE(car::read_chunk_file(out).size(), baseline().chunks.size() + 1);
}

// Case 5 of issue 19: random bytes, or lines that are not candump lines, ended "0 frames, exit 0".
TEST(HostileCar, AFileThatIsNoCanLogFailsNamingItAndWritesNothing) {
  ScratchDir scratch("hostile-not-a-log");
  std::mt19937 random(19);
  std::string bytes(400000, '\0');
  for (auto& b : bytes) b = static_cast<char>(random());
  std::string prose;
  for (int i = 0; i < 5000; ++i) prose += "line " + std::to_string(i) + ": this is not a candump line\n";
  std::string other_car;  // good lines of ids the profile's DBC does not know
  for (int i = 0; i < 500; ++i) other_car += "(1700000000." + std::to_string(100000 + i) + ") can0 7F0#0011223344556677\n";
  std::ostringstream mostly_bad;  // the real log with two bad lines after each good one
  {
    std::ostringstream good;
    can::CandumpWriter w(good);
    for (const auto& f : at_epoch(simulated_frames("tare"))) w.write(f);
    std::istringstream lines(good.str());
    for (std::string line; std::getline(lines, line);) mostly_bad << line << "\nnot a line\n#comment\n";
  }
  const std::vector<std::pair<std::string, std::string>> files{{"random.log", bytes},
                                                              {"prose.log", prose},
                                                              {"empty.log", ""},
                                                              {"other-car.log", other_car},
                                                              {"mostly-bad.log", mostly_bad.str()}};
  for (const auto& [name, text] : files) {
    SCOPED_TRACE(name);
    const auto log = scratch.path() / name;
    const auto out = scratch.path() / (name + ".chunks");
    write_text(log, text);
    const Outcome o = run(Program::Car, {"--profile", testcar_profile().string(), "--run", "r1", "--replay",
                                         log.string(), "--fast", "--chunks-out", out.string()},
                          scratch);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_NE(o.output.find(log.string() + ": not a CAN log this profile can use"), std::string::npos)
        << describe(o);
    EXPECT_FALSE(std::filesystem::exists(out)) << "nothing is written for a file that is no log";
    for (const char c : o.output)  // the file's bytes are shown escaped
      ASSERT_TRUE(c == '\n' || (c >= 0x20 && c < 0x7f)) << "unescaped byte " << int(c) << " in " << describe(o);
  }
}

// A line of megabytes of junk in a good log is one bad line: skipped to its end, every frame
// delivered. It once counted as one bad line per KiB and outvoted the frames around it ("most
// lines or objects are not CAN frames", exit 1); here 8192 pieces against 6000 frames would.
TEST(HostileCar, AJunkLineOfMegabytesIsOneBadLineAndEveryFrameIsDelivered) {
  ScratchDir scratch("hostile-long-line");
  const std::vector<can::Frame> all = at_epoch(simulated_frames());
  const std::vector<can::Frame> frames(all.begin(), all.begin() + 6000);
  std::ostringstream good;
  std::ostringstream junked;
  {
    can::CandumpWriter plain(good);
    can::CandumpWriter with_junk(junked);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      if (i == 3000) junked << std::string(8u << 20, 'x') << "\n";
      plain.write(frames[i]);
      with_junk.write(frames[i]);
    }
  }
  const auto chunks_of = [&](const std::string& name, const std::string& text) {
    const auto log = scratch.path() / (name + ".log");
    const auto out = scratch.path() / (name + ".chunks");
    write_text(log, text);
    const Outcome o = run(Program::Car,
                          {"--profile", testcar_profile().string(), "--run", "r1", "--replay",
                           log.string(), "--fast", "--chunks-out", out.string()},
                          scratch, 20s);
    return std::make_pair(o, std::filesystem::exists(out) ? read_text(out) : std::string());
  };
  const auto [plain_run, plain_chunks] = chunks_of("plain", good.str());
  ASSERT_EQ(plain_run.exit, 0) << describe(plain_run);
  const auto [junk_run, junk_chunks] = chunks_of("junk", junked.str());
  ASSERT_EQ(junk_run.exit, 0) << describe(junk_run);
  EXPECT_NE(junk_run.output.find("6000 frames (1 bad lines"), std::string::npos)
      << describe(junk_run);
  EXPECT_NE(junk_run.output.find(
                "junk.log:3001: line of 8388608 bytes, longer than the 1024 a line may have"),
            std::string::npos)
      << describe(junk_run);
  EXPECT_FALSE(plain_chunks.empty());
  EXPECT_TRUE(junk_chunks == plain_chunks) << "the junk line changes no chunk";
  EXPECT_LT(junk_run.seconds, 5.0) << describe(junk_run);
}

// A DBC whose multiplexed signals no frame can carry: m300 on an 8-bit switch, a switch that is
// a float, a switch that is itself in no frame. Such a DBC loads (with warnings); a profile that
// maps one of those signals to a channel is refused at load, naming the DBC's file:line, the
// message, the signal and why. It was accepted, and every row of the channel went invalid.
const std::string kUnreachableMuxDbc =
    "VERSION \"\"\n"
    "BO_ 100 MUXED: 8 X\n"
    " SG_ SEL M : 0|8@1+ (1,0) [0|0] \"\" X\n"
    " SG_ SPEED_300 m300 : 8|16@1+ (0.01,0) [0|0] \"m/s\" X\n"
    " SG_ SPEED_3 m3 : 8|16@1+ (0.01,0) [0|0] \"m/s\" X\n"
    "BO_ 200 FLOATSEL: 8 X\n"
    " SG_ FSEL M : 0|32@1+ (1,0) [0|0] \"\" X\n"
    " SG_ V m1 : 32|16@1+ (0.01,0) [0|0] \"m/s\" X\n"
    "BO_ 300 NESTED: 8 X\n"
    " SG_ OUTER M : 0|4@1+ (1,0) [0|0] \"\" X\n"
    " SG_ INNER m20M : 4|4@1+ (1,0) [0|0] \"\" X\n"
    " SG_ DEEP m1 : 8|16@1+ (0.01,0) [0|0] \"m/s\" X\n"
    "SIG_VALTYPE_ 200 FSEL : 1;\n"
    "SG_MUL_VAL_ 300 DEEP INNER 1-1;\n";

std::string mux_profile(const std::filesystem::path& dbc, const std::string& message,
                        const std::string& signal) {
  return "[vehicle]\nid = \"mux-car\"\ndbc = \"" + dbc.string() +
         "\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 1.0\n[spool]\ndirectory = "
         "\"spool\"\nmax_bytes = 1000000\n"
         "[[channels]]\nname = \"vx\"\nmessage = \"" +
         message + "\"\nsignal = \"" + signal + "\"\n";
}

TEST(HostileCar, AChannelWhoseMultiplexerValueItsSwitchCannotHoldIsRefusedAtLoad) {
  ScratchDir scratch("hostile-mux");
  const auto dbc = scratch.path() / "mux.dbc";
  write_text(dbc, kUnreachableMuxDbc);
  const auto log = scratch.path() / "can.log";
  write_log(log, at_epoch(simulated_frames("tare")));

  // The DBC loads: the message's reachable signal maps, and the parser says what it passed over.
  const auto good = scratch.path() / "good.toml";
  write_text(good, mux_profile(dbc, "MUXED", "SPEED_3"));
  const car::VehicleProfile loaded = car::load_vehicle_profile(good);
  EXPECT_EQ(loaded.channels.at(0).inputs.at(0).signal, "SPEED_3");
  EXPECT_EQ(loaded.dbc->warnings.size(), 4u) << "SPEED_300, V, INNER and DEEP";

  const std::vector<std::array<std::string, 3>> cases{
      {"MUXED", "SPEED_300",
       "mux.dbc:4: SG_ 'SPEED_300' of message 'MUXED' is in no frame: multiplexer value 300 is "
       "beyond what its "
       "switch 'SEL' (8 bits, 0..255) can hold"},
      {"FLOATSEL", "V",
       "mux.dbc:8: SG_ 'V' of message 'FLOATSEL' is in no frame: its switch 'FSEL' is a float "
       "signal"},
      {"NESTED", "DEEP",
       "mux.dbc:12: SG_ 'DEEP' of message 'NESTED' is in no frame: its switch 'INNER' is never "
       "present itself "
       "(line 11)"}};
  for (const auto& [message, signal, reason] : cases) {
    SCOPED_TRACE(signal);
    const auto profile = scratch.path() / (signal + ".toml");
    const auto out = scratch.path() / (signal + ".chunks");
    write_text(profile, mux_profile(dbc, message, signal));
    const Outcome o = run(Program::Car,
                          {"--profile", profile.string(), "--run", "r1", "--replay", log.string(),
                           "--fast", "--chunks-out", out.string()},
                          scratch);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_NE(o.output.find(profile.string() + ":13:"), std::string::npos) << describe(o);
    EXPECT_NE(o.output.find("channels[0].signal: DBC signal '" + signal + "' of message '" +
                            message + "' never gets a value"),
              std::string::npos)
        << describe(o);
    EXPECT_NE(o.output.find(reason), std::string::npos) << describe(o);
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

// A model listed without a channel it needs: the server would leave it "not run: the run has no
// channel ..." after the whole run was streamed. dynid-car refuses the run at start, naming each
// such model, what it lacks (a derived d_<x> with what it is made from) and the optional channels
// it lacks too, before anything is spooled, sent or written. (testcar.toml itself passes: its
// models' d_vx, d_yaw_rate, ... are derived from channels it has.)
TEST(HostileCar, AModelWithoutItsChannelsIsRefusedBeforeAnythingIsSent) {
  ScratchDir scratch("hostile-models");
  std::string text = read_text(testcar_profile());
  text.replace(text.find("dbc = \"../dbc/"), std::string("dbc = \"../dbc/").size(),
               "dbc = \"" + (source_dir() / "deploy" / "dbc").string() + "/");
  for (const std::string channel :
       {"yaw_rate", "roll"}) {  // each block: "[[channels]]\nname = ...\n..."
    const std::size_t at = text.find("[[channels]]\nname = \"" + channel + "\"");
    ASSERT_NE(at, std::string::npos) << channel;
    text.erase(at, text.find("[[channels]]", at + 1) - at);
  }
  const auto profile = scratch.path() / "no-yaw.toml";
  write_text(profile, text);
  const auto log = scratch.path() / "can.log";
  write_log(log, at_epoch(simulated_frames("tare")));
  const auto out = scratch.path() / "run.chunks";
  const auto spool = scratch.path() / "spool";
  const std::string config = "file://" + loopback_xml().string() +
                             ",<Discovery><Tag>dynid-hostile-models-" + std::to_string(getpid()) +
                             "</Tag></Discovery>";
  for (const auto& args :
       std::vector<std::vector<std::string>>{{"--chunks-out", out.string()},
                                             {"--cyclone-config", config, "--domain", "33",
                                              "--spool", spool.string(), "--drain-timeout", "1"}}) {
    SCOPED_TRACE(args.front());
    std::vector<std::string> all{"--profile", profile.string(), "--run", "r1",
                                 "--replay",  log.string(),     "--fast"};
    all.insert(all.end(), args.begin(), args.end());
    const Outcome o = run(Program::Car, all, scratch);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_NE(o.output.find(profile.string() +
                            ": 2 models of [[models]] cannot run on this run's channels"),
              std::string::npos)
        << describe(o);
    EXPECT_NE(
        o.output.find(
            "models[1] 'lateral_bicycle' needs 'yaw_rate' and 'd_yaw_rate' (the derivative of "
            "'yaw_rate'), which this run does not have (it would also read 'roll', optional, "
            "absent too)"),
        std::string::npos)
        << describe(o);
    EXPECT_NE(
        o.output.find(
            "models[3] 'kinematic_lateral' needs 'yaw_rate', which this run does not have (it "
            "would also read 'roll', optional, absent too)"),
        std::string::npos)
        << describe(o);
    EXPECT_LT(o.seconds, 3.0) << describe(o);
    EXPECT_FALSE(std::filesystem::exists(out)) << "no chunk written";
    EXPECT_FALSE(std::filesystem::exists(spool)) << "no spool made, nothing sent";
  }
}

// Case 4 of issue 19: a FIFO as the DBC, profile or log blocked dynid-car for ever. Every input
// that is not a regular file is refused at once, naming it and what it is.
TEST(HostileCar, InputsThatAreNotRegularFilesAreRefusedAtOnce) {
  ScratchDir scratch("hostile-not-files");
  const auto log = scratch.path() / "can.log";
  write_log(log, at_epoch(simulated_frames("tare")));
  const std::string text = read_text(testcar_profile());
  const std::string dbc = (source_dir() / "deploy" / "dbc" / "dynid_testcar.dbc").string();
  const auto profile_with_dbc = [&](const std::filesystem::path& d) {
    auto p = text;
    p.replace(p.find("../dbc/dynid_testcar.dbc"), std::string("../dbc/dynid_testcar.dbc").size(), d.string());
    const auto file = scratch.path() / ("profile-" + d.filename().string() + ".toml");
    write_text(file, p);
    return file;
  };
  for (const auto& [bad, kind] : not_regular_files(scratch)) {
    const std::vector<std::pair<std::string, std::vector<std::string>>> cases{
        {"profile", {"--profile", bad.string(), "--replay", log.string()}},
        {"DBC", {"--profile", profile_with_dbc(bad).string(), "--replay", log.string()}},
        {"log", {"--profile", testcar_profile().string(), "--replay", bad.string()}},
    };
    for (auto [what, args] : cases) {
      SCOPED_TRACE(what + " is a " + kind);
      const auto out = scratch.path() / "out.chunks";
      args.insert(args.end(), {"--run", "r1", "--fast", "--chunks-out", out.string()});
      const Outcome o = run(Program::Car, args, scratch, 5s);
      EXPECT_EQ(o.exit, 1) << describe(o);
      EXPECT_NE(o.output.find(bad.string()), std::string::npos) << describe(o);
      EXPECT_NE(o.output.find(kind), std::string::npos) << describe(o);
      EXPECT_FALSE(std::filesystem::exists(out));
    }
    SCOPED_TRACE("Cyclone configuration is a " + kind);
    const Outcome o = run(Program::Car,
                          {"--profile", testcar_profile().string(), "--cyclone-config", bad.string(), "--spool",
                           (scratch.path() / "spool").string(), "--replay", log.string(), "--fast", "--run", "r1"},
                          scratch, 5s);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_NE(o.output.find(kind), std::string::npos) << describe(o);
  }
}

// The chunk file is an output: a FIFO would block the writer until something reads it, a
// directory cannot hold it. Refused at once, naming it, before the log is read.
TEST(HostileCar, AChunkFileThatIsNoRegularFileIsRefusedAtOnce) {
  ScratchDir scratch("hostile-outputs");
  const auto log = scratch.path() / "can.log";
  write_log(log, at_epoch(simulated_frames("tare")));
  for (const auto& [bad, kind] : not_regular_files(scratch)) {
    if (kind == "character device") continue;  // /dev/null takes the chunks: a user's choice
    SCOPED_TRACE(kind);
    const Outcome o = run(Program::Car, {"--profile", testcar_profile().string(), "--replay", log.string(), "--run",
                                         "r1", "--fast", "--chunks-out", bad.string()},
                          scratch, 5s);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_NE(o.output.find(bad.string()), std::string::npos) << describe(o);
    EXPECT_NE(o.output.find(kind), std::string::npos) << describe(o);
  }
}

// A bus that cannot be read (a name no interface can have, one that does not exist, or a kernel
// without SocketCAN) fails before the chunk file is created.
TEST(HostileCar, ABusThatCannotBeReadLeavesNoChunkFile) {
  ScratchDir scratch("hostile-bus");
  const auto out = scratch.path() / "out.chunks";
  for (const std::string& name : {std::string(40, 'x'), std::string("a/b"), std::string("none0")}) {
    SCOPED_TRACE(name);
    const Outcome o = run(Program::Car, {"--profile", testcar_profile().string(), "--run", "r1", "--can", name,
                                         "--chunks-out", out.string()},
                          scratch, 5s);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_NE(o.output.find("SocketCAN"), std::string::npos) << describe(o);
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

// /dev/zero never ends: as a log it was read without end (memory grew with it); a sparse file of
// zeros is a regular file but would be one endless line.
TEST(HostileCar, EndlessInputIsRefusedOrReadInBoundedTime) {
  ScratchDir scratch("hostile-endless");
  const auto out = scratch.path() / "out.chunks";
  const auto sparse = scratch.path() / "sparse.log";
  { std::ofstream touch(sparse); }
  std::filesystem::resize_file(sparse, 100ull << 30);  // 100 GiB of zeros, no block used
  for (const std::string& bad : std::vector<std::string>{"/dev/zero", sparse.string()})
    for (const std::string option : {"--replay", "--profile"}) {
      SCOPED_TRACE(option + " " + bad);
      std::vector<std::string> args{"--profile", testcar_profile().string(), "--replay", bad, "--run", "r1",
                                    "--fast", "--chunks-out", out.string()};
      if (option == "--profile") args = {"--profile", bad, "--run", "r1", "--replay", bad, "--chunks-out", out.string()};
      const Outcome o = run(Program::Car, args, scratch, 10s);
      EXPECT_EQ(o.exit, 1) << describe(o);
      EXPECT_NE(o.output.find(bad), std::string::npos) << describe(o);
      EXPECT_FALSE(std::filesystem::exists(out));
    }
}

// Case 3 of issue 19 for dynid-car: every numeric option refuses what is not a number in its
// limits, naming the option, before doing anything.
TEST(HostileCar, NumericOptionsOutsideTheirLimitsAreRefused) {
  ScratchDir scratch("hostile-car-numbers");
  const auto log = scratch.path() / "can.log";
  write_log(log, at_epoch(simulated_frames("tare")));
  const auto out = scratch.path() / "out.chunks";
  const std::vector<std::string> base{"--profile", testcar_profile().string(), "--run", "r1", "--chunks-out",
                                      out.string()};
  const auto with = [&](std::vector<std::string> context) {
    context.insert(context.begin(), base.begin(), base.end());
    return context;
  };
  const std::vector<NumericOption> options{
      {"--speed", {"0", "0.0009", "1000.1"}, with({"--replay", log.string()})},
      {"--max-frames", {"0", "1e13"}, with({"--can", "vcan-none"})},
      {"--drain-timeout", {"-0.001", "86400.1"}, with({"--replay", log.string()})},
      {"--ack-timeout", {"0", "0.009", "86400.1"}, with({"--replay", log.string()})},
      {"--domain", {"-1", "231", "4294967296"}, with({"--replay", log.string()})},
  };
  for (const auto& option : options) expect_refused(Program::Car, option, 1, scratch, out);
  // At the limit, accepted: the fastest pace.
  const Outcome o = run(Program::Car, [&] {
    auto args = base;
    args.insert(args.end(), {"--replay", log.string(), "--speed", "1000"});
    return args;
  }(), scratch, 10s);
  EXPECT_EQ(o.exit, 0) << describe(o);
}

// Case 6 of issue 19 for dynid-car: a vehicle id or run name that could escape a path, match
// other partitions or forge a log line is refused, the message showing it escaped.
TEST(HostileCar, VehicleIdsAndRunNamesOutsideTheRuleAreRefused) {
  ScratchDir scratch("hostile-car-ids");
  const auto log = scratch.path() / "can.log";
  write_log(log, at_epoch(simulated_frames("tare")));
  const std::string text = read_text(testcar_profile());
  const auto out = scratch.path() / "out.chunks";
  const std::vector<std::pair<std::string, std::string>> bad{
      {"../../../escaped-vehicle", "'.'"}, {"a/b", "'/'"},         {".hidden", "'.'"},
      {"-rf", "'-'"},                     {"v*", "'*'"},          {"v?", "'?'"},
      {"a b", "' '"},                     {"line\nforged", "\\x0a"}, {std::string(65, 'v'), "65 characters"},
      {"caf\xc3\xa9", "\\xc3"},            {"v\\", "'\\\\'"}};
  for (const auto& [id, shown] : bad) {
    SCOPED_TRACE(id);
    auto p = text;
    p.replace(p.find("\"dynid-testcar\""), std::string("\"dynid-testcar\"").size(),
              "\"" + std::string(id == "line\nforged" ? "line\\nforged" : id == "v\\" ? "v\\\\" : id) + "\"");
    const auto profile = scratch.path() / "profile.toml";
    write_text(profile, p);
    Outcome o = run(Program::Car, {"--profile", profile.string(), "--replay", log.string(), "--fast", "--run", "r1",
                                   "--chunks-out", out.string()},
                    scratch, 5s);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_NE(o.output.find("vehicle.id"), std::string::npos) << describe(o);
    EXPECT_NE(o.output.find(shown), std::string::npos) << describe(o);
    o = run(Program::Car, {"--profile", testcar_profile().string(), "--replay", log.string(), "--fast", "--run=" + id,
                           "--chunks-out", out.string()},
            scratch, 5s);
    EXPECT_EQ(o.exit, 1) << describe(o);
    EXPECT_NE(o.output.find("run name"), std::string::npos) << describe(o);
    EXPECT_EQ(o.output.find("\nforged"), std::string::npos) << "no forged line: " << describe(o);
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

}  // namespace
}  // namespace dynid::hostile
