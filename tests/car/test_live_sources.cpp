// Auxiliary sources followed while a run is live (issue 17): a CSV file that grows or a named
// pipe a logger writes into, read as it is written (AuxiliaryFollower) and merged with the live
// bus (LiveMerge) so that the run's chunks equal, bit for bit, those of a replay of the same
// frames and the same file; a source that falls behind its wait costs samples, counted, never the
// bus; bad lines stop the source with the file and line.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <dynid/error.hpp>

#include "car_test_support.hpp"
#include "dynid/car/auxiliary.hpp"
#include "dynid/car/auxiliary_follower.hpp"
#include "dynid/car/live_merge.hpp"
#include "dynid/car/log_source.hpp"
#include "dynid/car/pipeline.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {
namespace {

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

const std::string kDbc = std::string(DYNID_SOURCE_DIR) + "/deploy/dbc/dynid_testcar.dbc";

// A logger with times in ms, offset 0.5 s to the bus.
AuxiliarySourceSpec logger_spec(const std::string& wait = "") {
  const std::string text =
      "[vehicle]\nid = \"aux-car\"\ndbc = \"" + kDbc +
      "\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 1.0\n[spool]\ndirectory = \"spool\"\nmax_bytes = 1000000\n"
      "[[channels]]\nname = \"vx\"\nmessage = \"ESP_Dynamics\"\nsignal = \"VehSpeed\"\n"
      "[[sources]]\nname = \"logger\"\ntype = \"csv\"\ntime_column = \"t\"\ntime_unit = \"ms\"\n"
      "clock = { offset = 0.5 }\n" + wait +
      "[[sources.channels]]\ncolumn = \"yaw\"\nchannel = \"yaw_rate\"\nunit = \"deg/s\"\n";
  return parse_vehicle_profile(text, "aux.toml").sources.at(0);
}

TEST(AuxiliaryFollower, TheProfileSetsEachSourcesWaitWithinItsLimits) {
  EXPECT_EQ(logger_spec().wait, 1.0);
  EXPECT_EQ(logger_spec("wait = 2.5\n").wait, 2.5);
  EXPECT_THROW(logger_spec("wait = 0\n"), InputError);
  EXPECT_THROW(logger_spec("wait = 31\n"), InputError);
}

void write_all(int fd, const std::string& text) {
  ASSERT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
}

TEST(AuxiliaryFollower, ReadsANamedPipeAsItIsWrittenAndEndsWhenTheWriterCloses) {
  test::ScratchDir dir("live-fifo");
  const auto fifo = dir.path() / "logger.pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  AuxiliaryFollower follower(logger_spec(), fifo, 0.5);  // opens before any writer, without blocking
  EXPECT_TRUE(follower.poll().empty());
  EXPECT_FALSE(follower.ended()) << "no writer yet is not the end";
  EXPECT_EQ(follower.complete_until(), -std::numeric_limits<double>::infinity());

  const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
  ASSERT_GE(writer, 0);
  write_all(writer, "t,yaw,other\n0,57.29577951308232,x\n10,");
  auto rows = follower.poll();
  ASSERT_EQ(rows.size(), 1u) << "a line is complete at its newline";
  EXPECT_DOUBLE_EQ(rows[0].time, 0.5);
  EXPECT_NEAR(rows[0].values[0], 1.0, 1e-15) << "deg/s in SI";
  EXPECT_DOUBLE_EQ(follower.complete_until(), 0.5);

  write_all(writer, "0,y\n20,57.29577951308232,z");  // the last line has no newline yet
  rows = follower.poll();
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_DOUBLE_EQ(rows[0].time, 0.51);
  EXPECT_DOUBLE_EQ(rows[0].values[0], 0.0);
  ::close(writer);
  rows = follower.poll();
  ASSERT_EQ(rows.size(), 1u) << "the writer closing completes the last line";
  EXPECT_DOUBLE_EQ(rows[0].time, 0.52);
  EXPECT_TRUE(follower.ended());
  EXPECT_FALSE(follower.error());
  EXPECT_EQ(follower.complete_until(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(follower.rows(), 3u);
}

TEST(AuxiliaryFollower, AGrowingFileIsFollowedAndABadLineStopsItNamingFileAndLine) {
  test::ScratchDir dir("live-file");
  const auto file = dir.path() / "logger.csv";
  std::ofstream out(file);
  out << "t,yaw\n0,1\n" << std::flush;
  AuxiliaryFollower follower(logger_spec(), file, 0.5);
  EXPECT_EQ(follower.poll().size(), 1u);
  out << "10,2\n" << std::flush;
  EXPECT_EQ(follower.poll().size(), 1u);
  EXPECT_TRUE(follower.poll().empty());
  EXPECT_FALSE(follower.ended()) << "a file that stops growing has not ended: the writer may be slow";
  out << "5,3\n30,4\n" << std::flush;  // unsorted
  EXPECT_TRUE(follower.poll().empty());
  ASSERT_TRUE(follower.error());
  EXPECT_HAS(*follower.error(), "logger.csv:4:");
  EXPECT_HAS(*follower.error(), "sorted");
  EXPECT_TRUE(follower.ended());
  EXPECT_EQ(follower.rows(), 2u) << "what came before the bad line is kept";
}

TEST(AuxiliaryFollower, AFileThatShrinksOrAnUnknownColumnStopsIt) {
  test::ScratchDir dir("live-shrink");
  const auto file = dir.path() / "logger.csv";
  { std::ofstream(file) << "t,yaw\n0,1\n10,2\n"; }
  AuxiliaryFollower follower(logger_spec(), file, 0.0);
  EXPECT_EQ(follower.poll().size(), 2u);
  { std::ofstream(file) << "t,yaw\n"; }  // rewritten from the start
  follower.poll();
  ASSERT_TRUE(follower.error());
  EXPECT_HAS(*follower.error(), "shrank");

  const auto other = dir.path() / "other.csv";
  { std::ofstream(other) << "time,yaw\n0,1\n"; }
  AuxiliaryFollower wrong(logger_spec(), other, 0.0);
  wrong.poll();
  ASSERT_TRUE(wrong.error());
  EXPECT_HAS(*wrong.error(), "other.csv:1:");
  EXPECT_HAS(*wrong.error(), "no column 't'");
}

TEST(AuxiliaryFollower, RefusesWhatCannotBeFollowedBeforeTheRun) {
  test::ScratchDir dir("live-refused");
  EXPECT_THROW(AuxiliaryFollower(logger_spec(), dir.path() / "absent.csv", 0.0), InputError);
  EXPECT_THROW(AuxiliaryFollower(logger_spec(), dir.path(), 0.0), InputError);  // a folder
}

// ---- the RAV4 run, live against replayed -----------------------------------------------------

// rav4.toml with the recorder IMU's clock fixed (a live run cannot estimate it): the offset the
// replay estimates, -0.201 s.
VehicleProfile rav4_with_fixed_imu_clock() {
  const auto path = test::profile_path("rav4.toml");
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  std::string s = text.str();
  const std::size_t at = s.find("clock = { estimate_from");
  const std::size_t end = s.find('\n', at);
  s.replace(at, end - at, "clock = { offset = -0.201 }");
  return parse_vehicle_profile(s, path);
}

std::vector<ingest::Chunk> replayed(const VehicleProfile& declared, const std::filesystem::path& imu) {
  RunSources sources = prepare_sources(declared, {{"recorder_imu", imu}}, nullptr, false);
  std::vector<ingest::Chunk> chunks;
  CarPipeline pipe(sources.profile, "live", [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
  pipe.add_auxiliary(std::move(sources.samples));
  LogSource log(test::rav4_log());
  can::Frame frame;
  while (log.next(frame, std::chrono::milliseconds(0)) == NextStatus::Frame) pipe.on_frame(frame);
  pipe.finish();
  return chunks;
}

// The IMU's lines, and each one's time on the bus's clock.
struct ImuLines {
  std::string header;
  std::vector<std::pair<double, std::string>> rows;
};

ImuLines imu_lines(const std::filesystem::path& imu, double offset) {
  ImuLines out;
  std::ifstream in(imu);
  std::getline(in, out.header);
  for (std::string line; std::getline(in, line);) out.rows.emplace_back(std::stod(line.substr(0, line.find(','))) + offset, line);
  return out;
}

struct LiveResult {
  std::vector<ingest::Chunk> chunks;
  LiveMergeStats stats;
  std::vector<std::string> report;
};

// The bus live (frames of the log, the wall clock 2 ms behind each), the IMU written into a named
// pipe `lag` seconds behind the bus.
LiveResult live(const VehicleProfile& declared, const std::filesystem::path& imu, const test::ScratchDir& dir, double lag) {
  const auto fifo = dir.path() / "imu.pipe";
  std::filesystem::remove(fifo);
  EXPECT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  RunSources sources = prepare_sources(declared, {{"recorder_imu", fifo}}, nullptr, true);
  EXPECT_TRUE(sources.samples.empty());
  EXPECT_EQ(sources.followed.size(), 1u);
  int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
  EXPECT_GE(writer, 0);
  const ImuLines lines = imu_lines(imu, -0.201);
  std::size_t written = 0;
  bool header_written = false;
  const auto write_until = [&](double bus_time) {
    std::string block = header_written ? "" : lines.header + "\n";
    header_written = true;
    for (; written < lines.rows.size() && lines.rows[written].first <= bus_time; ++written)
      block += lines.rows[written].second + "\n";
    if (!block.empty()) {
      EXPECT_EQ(::write(writer, block.data(), block.size()), static_cast<ssize_t>(block.size()));
    }
    if (written == lines.rows.size() && writer >= 0) {  // the logger is done: the pipe ends
      ::close(writer);
      writer = -1;
    }
  };

  LiveResult result;
  CarPipeline pipe(sources.profile, "live", [&](ingest::Chunk&& c) { result.chunks.push_back(std::move(c)); });
  LiveMerge merge(pipe, std::move(sources.followed));
  LogSource log(test::rav4_log());
  can::Frame frame;
  while (log.next(frame, std::chrono::milliseconds(0)) == NextStatus::Frame) {
    const double now = frame.timestamp + 0.002;
    write_until(now - lag);
    merge.on_frame(frame, now);
  }
  write_until(std::numeric_limits<double>::infinity());
  merge.finish();
  result.stats = merge.stats();
  result.report = merge.report();
  return result;
}

void expect_same_chunks(const std::vector<ingest::Chunk>& a, const std::vector<ingest::Chunk>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].checksum, b[i].checksum) << "chunk " << i;
    EXPECT_EQ(a[i].valid, b[i].valid) << "chunk " << i;
    EXPECT_TRUE(a[i].samples.cwiseEqual(b[i].samples).all()) << "chunk " << i;
  }
}

TEST(LiveMerge, ALiveRunWithTheImuInANamedPipeCutsTheChunksOfItsReplay) {
  DYNID_REQUIRE_RAV4_DATA();
  test::ScratchDir dir("live-rav4");
  const VehicleProfile declared = rav4_with_fixed_imu_clock();
  const auto imu = test::rav4_data_dir() / "phone_imu_accel.csv";
  const auto reference = replayed(declared, imu);
  ASSERT_GT(reference.size(), 50u);

  // The IMU 0.3 s behind the bus, within its wait (1 s): the frames wait for it.
  const LiveResult on_time = live(declared, imu, dir, 0.3);
  expect_same_chunks(on_time.chunks, reference);
  EXPECT_GT(on_time.stats.frames_held, 1000u);
  EXPECT_EQ(on_time.stats.frames_forced, 0u);
  EXPECT_EQ(on_time.stats.late, 0u);
  ASSERT_EQ(on_time.report.size(), 1u);
  EXPECT_HAS(on_time.report[0], "followed live");
  EXPECT_EQ(on_time.report[0].find("dropped"), std::string::npos) << on_time.report[0];

  // 2 s behind, past its wait: the bus goes on, the IMU's late samples are counted and dropped,
  // and the log says which wait to raise.
  const LiveResult behind = live(declared, imu, dir, 2.0);
  EXPECT_GT(behind.stats.frames_forced, 1000u);
  EXPECT_GT(behind.stats.late, 100u);
  EXPECT_HAS(behind.report[0], "raise [[sources]] wait");
  ASSERT_EQ(behind.chunks.size(), reference.size()) << "the bus loses nothing to a slow source";
  std::size_t valid_behind = 0, valid_reference = 0;
  for (const auto& c : behind.chunks) for (auto v : c.valid) valid_behind += v;
  for (const auto& c : reference) for (auto v : c.valid) valid_reference += v;
  EXPECT_LT(valid_behind, valid_reference) << "rows without their IMU sample are not valid";
}

TEST(LiveMerge, WithoutSourcesEveryFrameGoesStraightThrough) {
  DYNID_REQUIRE_RAV4_DATA();
  const VehicleProfile declared = rav4_with_fixed_imu_clock();
  RunSources sources = prepare_sources(declared, {}, nullptr, true);
  std::vector<ingest::Chunk> direct, merged;
  CarPipeline a(sources.profile, "r", [&](ingest::Chunk&& c) { direct.push_back(std::move(c)); });
  CarPipeline b(sources.profile, "r", [&](ingest::Chunk&& c) { merged.push_back(std::move(c)); });
  LiveMerge merge(b, {});
  LogSource log(test::rav4_log());
  can::Frame frame;
  while (log.next(frame, std::chrono::milliseconds(0)) == NextStatus::Frame) {
    a.on_frame(frame);
    merge.on_frame(frame, frame.timestamp + 100.0);  // whatever the wall clock says
  }
  a.finish();
  merge.finish();
  expect_same_chunks(merged, direct);
  EXPECT_EQ(merge.stats().frames_held, 0u);
}

TEST(LiveMerge, ALiveRunRefusesACanSourceWithoutAnInterfaceOpenerAndAnEstimatedClock) {
  const std::string chassis =
      "[vehicle]\nid = \"aux-car\"\ndbc = \"" + kDbc +
      "\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 1.0\n[spool]\ndirectory = \"spool\"\nmax_bytes = 1000000\n"
      "[[channels]]\nname = \"vx\"\nmessage = \"ESP_Dynamics\"\nsignal = \"VehSpeed\"\n"
      "[[sources]]\nname = \"chassis\"\ntype = \"can\"\ndbc = \"" + kDbc + "\"\nclock = { offset = 0.0 }\n"
      "[[sources.channels]]\nname = \"yaw_rate\"\nmessage = \"ESP_Dynamics\"\nsignal = \"YawRate\"\n";
  try {
    (void)prepare_sources(parse_vehicle_profile(chassis, "aux.toml"), {{"chassis", "can1"}}, nullptr, true);
    ADD_FAILURE() << "a CAN source live without an opener";
  } catch (const InputError& e) {
    EXPECT_HAS(std::string(e.what()), "only by dynid-car");
  }

  DYNID_REQUIRE_RAV4_DATA();
  const VehicleProfile estimated = load_vehicle_profile(test::profile_path("rav4.toml"));
  const auto imu = test::rav4_data_dir() / "phone_imu_accel.csv";
  try {
    (void)prepare_sources(estimated, {{"recorder_imu", imu}}, nullptr, true);
    ADD_FAILURE() << "an estimated clock in a live run";
  } catch (const InputError& e) {
    EXPECT_HAS(std::string(e.what()), "offset = <seconds>");
  }
}

}  // namespace
}  // namespace dynid::car
