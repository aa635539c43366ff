// Auxiliary sources (issue 17): a CSV source declared in the profile, merged into the run's grid
// with the same gap and validity rules as bus channels, its clock fixed or estimated; and bad
// auxiliary data (unknown columns, unsorted times, missing units, a drifting clock) refused with
// a message naming the file, the line or the key. An MDF4 file of signals is a source as its CSV
// is.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include <dynid/can/candump.hpp>
#include <dynid/can/encoder.hpp>
#include <dynid/can/mdf4.hpp>
#include <dynid/error.hpp>

#include "car_test_support.hpp"
#include "dynid/car/auxiliary.hpp"
#include "dynid/car/clock_offset.hpp"
#include "dynid/car/pipeline.hpp"
#include "dynid/car/vehicle_profile.hpp"
#include "dynid/report/mdf4_writer.hpp"

namespace dynid::car {
namespace {

const std::string kDbc = std::string(DYNID_SOURCE_DIR) + "/deploy/dbc/dynid_testcar.dbc";

std::string profile_text(const std::string& sources) {
  return "[vehicle]\nid = \"aux-car\"\ndbc = \"" + kDbc +
         "\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 1.0\n[spool]\ndirectory = \"spool\"\nmax_bytes = 1000000\n"
         "[[channels]]\nname = \"vx\"\nmessage = \"ESP_Dynamics\"\nsignal = \"VehSpeed\"\n"
         "[[channels]]\nname = \"ax\"\nmessage = \"ESP_Dynamics\"\nsignal = \"LongAccel\"\n" +
         sources;
}

const std::string kLogger =
    "[[sources]]\nname = \"logger\"\ntype = \"csv\"\ntime_column = \"t\"\ntime_unit = \"ms\"\n"
    "clock = { offset = 0.5 }\n"
    "[[sources.channels]]\ncolumn = \"acc\"\nchannel = \"ax\"\nunit = \"m/s^2\"\nreplaces_bus = true\n"
    "[[sources.channels]]\ncolumn = \"yaw\"\nchannel = \"yaw_rate\"\nunit = \"deg/s\"\n";

VehicleProfile profile(const std::string& sources) {
  return parse_vehicle_profile(profile_text(sources), "aux.toml");
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

// A logger file: t in ms from 0 to 10 s at 50 Hz, acc = t (s), yaw = 180/pi deg/s; rows within
// [skip_from, skip_to) s left out.
std::filesystem::path write_logger(const test::ScratchDir& dir, double skip_from = -1, double skip_to = -1) {
  const auto path = dir.path() / "logger.csv";
  std::ofstream out(path);
  out.precision(17);
  out << "t,acc,yaw,unused\n";
  for (int i = 0; i <= 500; ++i) {
    const double t = i * 0.02;
    if (t >= skip_from && t < skip_to) continue;
    out << t * 1000.0 << "," << t << "," << 180.0 / std::numbers::pi << ",7\n";
  }
  return path;
}

// Bus frames of ESP_Dynamics (all zero: vx 0 km/h) at 100 Hz from 1 s to 9 s.
std::vector<ingest::Chunk> run_pipeline(const RunSources& sources) {
  std::vector<ingest::Chunk> chunks;
  CarPipeline pipe(sources.profile, "r1", [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
  pipe.add_auxiliary(sources.samples);
  can::Frame f;
  f.id = 176;
  f.length = 8;
  f.set_interface_name("can0");
  for (int i = 100; i <= 900; ++i) {
    f.timestamp = i * 0.01;
    pipe.on_frame(f);
  }
  pipe.finish();
  return chunks;
}

TEST(CarAuxiliary, ADeclaredSourceNotGivenLeavesTheBusProfileAsItIs) {
  const VehicleProfile declared = profile(kLogger);
  ASSERT_EQ(declared.sources.size(), 1u);
  const RunSources run = prepare_sources(declared, {}, nullptr);
  ASSERT_EQ(run.profile.channels.size(), 2u);
  EXPECT_FALSE(run.profile.channels[1].source);  // ax still from the bus
  EXPECT_TRUE(run.samples.empty());
  EXPECT_HAS(run.reports.at(0).describe(), "not given for this run (--source logger=FILE): left out");
}

TEST(CarAuxiliary, MergedOntoTheGridInSiUnitsOnTheBusClock) {
  test::ScratchDir dir("aux-merge");
  const RunSources run = prepare_sources(profile(kLogger), {{"logger", write_logger(dir)}}, nullptr);
  ASSERT_EQ(run.profile.channels.size(), 3u);
  EXPECT_EQ(run.profile.channels[1].channel, "ax");  // replaced in place: the column order stays
  EXPECT_TRUE(run.profile.channels[1].source);
  EXPECT_EQ(run.profile.channels[2].channel, "yaw_rate");
  EXPECT_HAS(run.reports.at(0).describe(), "clock offset +0.500 s (fixed in the profile)");
  EXPECT_HAS(run.reports.at(0).describe(), "columns not mapped: unused");
  const auto announcement = run.profile.announcement("r1");
  EXPECT_EQ(announcement.channels.size(), 3u);

  const auto chunks = run_pipeline(run);
  ASSERT_FALSE(chunks.empty());
  std::size_t valid = 0;
  for (const auto& c : chunks)
    for (Eigen::Index k = 0; k < c.samples.rows(); ++k) {
      if (!c.valid[static_cast<std::size_t>(k)]) continue;
      ++valid;
      // Row time on the bus clock: 1 s + (index / 100 Hz); the logger's acc there is t - 0.5.
      const double t = 1.0 + static_cast<double>(c.first_sample_index + static_cast<std::uint64_t>(k)) / 100.0;
      EXPECT_NEAR(c.samples(k, 1), t - 0.5, 1e-9);
      EXPECT_NEAR(c.samples(k, 2), 1.0, 1e-12);  // 180/pi deg/s = 1 rad/s
    }
  EXPECT_GT(valid, 750u);
}

TEST(CarAuxiliary, ASecondBusLogWithItsOwnDbcIsASource) {
  const VehicleProfile declared = profile(
      "[[sources]]\nname = \"chassis\"\ntype = \"can\"\ndbc = \"" + kDbc + "\"\ninterfaces = [\"can1\"]\n"
      "clock = { offset = 0.25 }\n[[sources.channels]]\nname = \"yaw_rate\"\nmessage = \"ESP_Dynamics\"\n"
      "signal = \"YawRate\"\n");
  test::ScratchDir dir("aux-can");
  const auto log = dir.path() / "chassis.log";
  {
    std::ofstream out(log);
    can::CandumpWriter writer(out);
    const can::Message& m = *declared.sources.at(0).bus->dbc->find_message("ESP_Dynamics");
    for (int i = 0; i <= 1000; ++i) {
      can::Frame f;
      const can::SignalValue yaw{"YawRate", 57.3};
      ASSERT_TRUE(can::encode_frame(m, std::span(&yaw, 1), f).ok());
      f.timestamp = i * 0.01;
      f.set_interface_name(i % 2 ? "can1" : "can7");  // can7: not this source's bus
      writer.write(f);
    }
  }
  const RunSources run = prepare_sources(declared, {{"chassis", log}}, nullptr);
  ASSERT_EQ(run.profile.channels.size(), 3u);
  EXPECT_EQ(run.profile.channels[2].channel, "yaw_rate");
  EXPECT_EQ(run.reports.at(0).samples, 500u);  // the can1 frames only
  const auto chunks = run_pipeline(run);
  std::size_t valid = 0;
  for (const auto& c : chunks)
    for (Eigen::Index k = 0; k < c.samples.rows(); ++k)
      if (c.valid[static_cast<std::size_t>(k)]) {
        ++valid;
        EXPECT_NEAR(c.samples(k, 2), 57.3 * std::numbers::pi / 180.0, 1e-12);
      }
  EXPECT_GT(valid, 750u);
  EXPECT_HAS(error_of([&] { (void)profile("[[sources]]\nname = \"c\"\ntype = \"can\"\ndbc = \"" + kDbc +
                                          "\"\nclock = { offset = 0.0 }\n[[sources.channels]]\nname = \"yaw_rate\"\n"
                                          "message = \"NoSuchMessage\"\nsignal = \"X\"\n"); }),
             "sources[0].channels[0].message: unknown DBC message 'NoSuchMessage'");
}

// Issue 38, item 3: the logger's rows as an ASAM MDF4 file of physical channels are the same
// source as its CSV file: the same chunks, value for value. Its channels are chosen by name,
// wherever they are; a name no group or two groups hold is an error naming the groups.
TEST(CarAuxiliary, AnMdf4FileOfSignalsIsTheSameSourceAsItsCsv) {
  test::ScratchDir dir("aux-mdf4");
  const RunSources from_csv =
      prepare_sources(profile(kLogger), {{"logger", write_logger(dir)}}, nullptr);
  report::Mdf4Table table{"logger", "", {}, {{"acc", "m/s^2", "", {}}, {"yaw", "deg/s", "", {}}}};
  for (int i = 0; i <= 500; ++i) {
    const double t = i * 0.02;
    table.time_s.push_back(t * 1000.0 * 1e-3);  // the CSV's time in ms, read as seconds
    table.columns[0].values.push_back(t);
    table.columns[1].values.push_back(180.0 / std::numbers::pi);
  }
  const auto write = [&](const std::vector<report::Mdf4Table>& tables) {
    const auto path = dir.path() / "logger.mf4";
    std::ofstream(path, std::ios::binary) << report::write_mdf4({0, "", tables});
    return path;
  };
  std::string mdf4_logger = kLogger;
  const std::string csv_keys = "type = \"csv\"\ntime_column = \"t\"\ntime_unit = \"ms\"\n";
  mdf4_logger.replace(mdf4_logger.find(csv_keys), csv_keys.size(), "type = \"mdf4\"\n");
  const RunSources from_mdf4 =
      prepare_sources(profile(mdf4_logger), {{"logger", write({table})}}, nullptr);
  EXPECT_TRUE(from_mdf4.reports.at(0).warnings.empty()) << from_mdf4.reports.at(0).describe();
  EXPECT_EQ(from_mdf4.reports.at(0).samples, from_csv.reports.at(0).samples);
  const auto a = run_pipeline(from_csv), b = run_pipeline(from_mdf4);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].valid, b[k].valid) << "chunk " << k;
    EXPECT_EQ(a[k].samples, b[k].samples) << "chunk " << k;
  }
  table.columns[1].unit = "rad/s";
  const RunSources other_unit =
      prepare_sources(profile(mdf4_logger), {{"logger", write({table})}}, nullptr);
  ASSERT_EQ(other_unit.reports.at(0).warnings.size(), 1U);
  EXPECT_EQ(
      other_unit.reports.at(0).warnings[0],
      "channel 'yaw': the file says 'rad/s', the profile 'deg/s': the profile's unit is used");
  report::Mdf4Table second = table;
  second.name = "logger2";
  EXPECT_HAS(
      error_of([&] {
        (void)prepare_sources(profile(mdf4_logger), {{"logger", write({table, second})}}, nullptr);
      }),
      "source 'logger': channel 'acc' is in 2 channel groups: which one is meant cannot be told "
      "(its channel groups: 'logger', 'logger2')");
  table.columns[0].name = "accel";
  EXPECT_HAS(error_of([&] {
               (void)prepare_sources(profile(mdf4_logger), {{"logger", write({table})}}, nullptr);
             }),
             "source 'logger': no channel 'acc' in the file (its channel groups: 'logger')");
}

// A real decoded file (asammdf 7.0's decode of a CANedge log, ../shared/data) as an MDF4 source:
// every value of the channel, on the header's clock.
TEST(CarAuxiliary, AnAsammdfDecodedFileIsAnMdf4Source) {
  const auto decoded = std::filesystem::path(DYNID_SHARED_DATA) / "mdf4-canedge" / "decoded" /
                       "3BA199E2_00000164_00000001-60FE3F04.mf4";
  if (!std::filesystem::exists(decoded)) GTEST_SKIP() << decoded << " is absent (../shared/data)";
  const RunSources run = prepare_sources(
      profile(
          "[[sources]]\nname = \"decoded\"\ntype = \"mdf4\"\nclock = { offset = 0.0 }\n"
          "[[sources.channels]]\ncolumn = \"AccelerationY\"\nchannel = \"ay\"\nunit = \"m/s^2\"\n"),
      {{"decoded", decoded}}, nullptr);
  const can::Mdf4File file(decoded);
  std::uint64_t expected = 0;
  for (const auto& dg : file.data_groups())
    for (const auto& g : dg.groups)
      if (g.find("AccelerationY") != nullptr) expected += g.cycle_count;
  EXPECT_GT(expected, 1000U);
  EXPECT_EQ(run.reports.at(0).samples, expected);
  EXPECT_TRUE(run.reports.at(0).warnings.empty()) << run.reports.at(0).describe();
  ASSERT_FALSE(run.samples.empty());
  // Seconds since 1970: the recording is of 2021.
  EXPECT_GT(run.samples.front().time, 1.6e9);
  EXPECT_LT(run.samples.front().time, 1.7e9);
}

TEST(CarAuxiliary, AGapInTheSourceIsAGapOfItsChannelAsOnTheBus) {
  test::ScratchDir dir("aux-gap");
  // No logger rows from 4 to 5 s of its clock: 4.5 .. 5.5 s on the bus.
  const RunSources run = prepare_sources(profile(kLogger), {{"logger", write_logger(dir, 4.0, 5.0)}}, nullptr);
  const auto chunks = run_pipeline(run);
  std::size_t invalid_in_gap = 0, invalid_elsewhere = 0;
  for (const auto& c : chunks)
    for (Eigen::Index k = 0; k < c.samples.rows(); ++k) {
      const double t = 1.0 + static_cast<double>(c.first_sample_index + static_cast<std::uint64_t>(k)) / 100.0;
      if (c.valid[static_cast<std::size_t>(k)]) continue;
      (t > 4.5 && t < 5.5 ? invalid_in_gap : invalid_elsewhere)++;
    }
  EXPECT_GE(invalid_in_gap, 95u);  // the second without data, not bridged by interpolation
  EXPECT_LT(invalid_elsewhere, 10u);
}

TEST(CarAuxiliary, BadAuxiliaryDataIsNamed) {
  test::ScratchDir dir("aux-bad");
  const auto write = [&](const std::string& text) {
    const auto p = dir.path() / "bad.csv";
    std::ofstream(p) << text;
    return p;
  };
  const VehicleProfile declared = profile(kLogger);
  const auto given = [&](const std::string& text) {
    return error_of([&] { (void)prepare_sources(declared, {{"logger", write(text)}}, nullptr); });
  };
  EXPECT_HAS(given("t,acc\n0,1\n"), "bad.csv:1: auxiliary source 'logger': no column 'yaw' in the header (columns: t, acc)");
  EXPECT_HAS(given("t,acc,yaw\n0,1,2\n20,1,2\n10,1,2\n"),
             "bad.csv:4: time 0.010000 s is before the previous row's 0.020000 s: the rows must be sorted by time");
  EXPECT_HAS(given("t,acc,yaw\n0,1,2\n10,x1,2\n"), "bad.csv:3: column 'acc': 'x1' is not a number");
  EXPECT_HAS(given("t,acc,yaw\n0,1,2\n10,1\n"), "bad.csv:3: 2 cells, the header has 3");
  EXPECT_HAS(given("t,acc,yaw\n0,1,2\nnow,1,2\n"), "bad.csv:3: time 'now' is not a finite number");
  EXPECT_HAS(given(""), "empty file");
  // Warnings say what was done.
  const RunSources run = prepare_sources(declared, {{"logger", write("t,acc,yaw\n0,1,2\n10,1,2\n10,5,5\n20,nan,2\n30,,2\n")}}, nullptr);
  const auto& w = run.reports.at(0).warnings;
  ASSERT_EQ(w.size(), 2u);
  EXPECT_HAS(w[0], "1 rows repeating the previous row's time dropped");
  EXPECT_HAS(w[1], "1 non-finite values (nan, inf) left out");
  EXPECT_EQ(run.reports.at(0).samples, 6u);  // 4 rows x 2 channels, less the nan and the empty cell
  EXPECT_HAS(error_of([&] { (void)prepare_sources(declared, {{"gps", "x.csv"}}, nullptr); }),
             "--source gps=x.csv: the profile aux.toml declares no source 'gps' (declared: logger)");
}

TEST(CarAuxiliary, BadSourceDeclarationsAreNamed) {
  const auto declared = [](const std::string& s) { return error_of([&] { (void)profile(s); }); };
  const std::string head = "[[sources]]\nname = \"logger\"\ntype = \"csv\"\ntime_column = \"t\"\ntime_unit = \"s\"\n";
  EXPECT_HAS(declared(head + "clock = { offset = 0.0 }\n[[sources.channels]]\ncolumn = \"a\"\nchannel = \"az\"\n"),
             "sources[0].channels[0].unit: missing unit: give the unit of column 'a' (channel 'az' is in 'm/s^2'");
  EXPECT_HAS(declared(head + "clock = { offset = 0.0 }\n[[sources.channels]]\ncolumn = \"a\"\nchannel = \"az\"\nunit = \"km/h\"\n"),
             "cannot convert column 'a' from 'km/h' to 'm/s^2'");
  EXPECT_HAS(declared(head + "clock = { offset = 0.0 }\n[[sources.channels]]\ncolumn = \"a\"\nchannel = \"ax\"\nunit = \"g\"\n"),
             "channel 'ax' is also a bus channel ([[channels]]): say replaces_bus = true");
  EXPECT_HAS(declared(head + "[[sources.channels]]\ncolumn = \"a\"\nchannel = \"az\"\nunit = \"g\"\n"),
             "sources[0].clock: missing: give clock = { offset = <s> }");
  EXPECT_HAS(declared(head + "clock = { estimate_from = \"az\", reference = \"yaw_rate\" }\n[[sources.channels]]\n"
                             "column = \"a\"\nchannel = \"az\"\nunit = \"g\"\n"),
             "sources[0].clock.reference: 'yaw_rate' is not a bus channel");
  EXPECT_HAS(declared(head + "clock = { offset = 0.0 }\ncolumns = 3\n[[sources.channels]]\ncolumn = \"a\"\nchannel = \"az\"\nunit = \"g\"\n"),
             "sources[0].columns: unknown key");
  EXPECT_HAS(declared("[[sources]]\ntype = \"csv\"\nname = \"../x\"\n"), "sources[0].name: '../x'");
  // Estimated clocks need the replayed log.
  const VehicleProfile estimated = profile(head + "clock = { estimate_from = \"az\", reference = \"ax\" }\n"
                                                  "[[sources.channels]]\ncolumn = \"a\"\nchannel = \"az\"\nunit = \"g\"\n");
  test::ScratchDir dir("aux-live");
  std::ofstream(dir.path() / "a.csv") << "t,a\n0,1\n1,2\n";
  EXPECT_HAS(error_of([&] { (void)prepare_sources(estimated, {{"logger", dir.path() / "a.csv"}}, nullptr); }),
             "its clock offset is estimated from the replayed log; a live run has none");
}

// A smooth random signal (sum of sines of random phases from 0.2 to 3 Hz).
TimeSeries signal(double t0, double t1, double rate, double shift, double stretch, unsigned seed, double noise) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> phase(0, 2 * std::numbers::pi);
  std::normal_distribution<double> n(0.0, noise);
  std::vector<std::pair<double, double>> waves;
  for (int i = 0; i < 12; ++i) waves.emplace_back(0.2 + 0.25 * i, phase(rng));
  std::mt19937 rng2(seed + 1);
  TimeSeries s;
  for (double t = t0; t < t1; t += 1.0 / rate) {
    const double bus = (t + shift) * stretch;  // the bus time this source time stands for
    double v = 0;
    for (const auto& [f, p] : waves) v += std::sin(2 * std::numbers::pi * f * bus + p) / (1 + f);
    s.t.push_back(t);
    s.v.push_back(v + n(rng2));
  }
  return s;
}

TEST(CarAuxiliaryClock, EstimatesAKnownOffsetWithItsStd) {
  const TimeSeries bus = signal(0, 120, 83, 0, 1, 7, 0.05);
  const TimeSeries src = signal(10, 110, 104, 0.3, 1, 7, 0.2);  // bus time = source time + 0.3
  const ClockEstimate e = estimate_clock_offset(bus, src, {}, "test");
  std::printf("offset %.4f +- %.4f s (true 0.3), correlation %.2f\n", e.offset, e.std, e.correlation);
  EXPECT_NEAR(e.offset, 0.3, std::max(3 * e.std, 0.005));
  EXPECT_LT(e.std, 0.01);
  EXPECT_FALSE(e.drifting());
}

TEST(CarAuxiliaryClock, ADriftingClockIsFound) {
  const TimeSeries bus = signal(0, 120, 83, 0, 1, 9, 0.05);
  const TimeSeries src = signal(10, 110, 104, 0.0, 1.004, 9, 0.2);  // 0.4 s over 100 s
  const ClockEstimate e = estimate_clock_offset(bus, src, {}, "test");
  std::printf("start %.3f +- %.3f s, end %.3f +- %.3f s, drift %.5f +- %.5f s/s (true 0.004)\n", e.start, e.start_std,
              e.end, e.end_std, e.drift, e.drift_std);
  EXPECT_TRUE(e.drifting());
}

TEST(CarAuxiliaryClock, NoExcitationIsNoEstimate) {
  TimeSeries flat_bus, flat_src;
  for (int i = 0; i < 6000; ++i) {
    flat_bus.t.push_back(i * 0.01), flat_bus.v.push_back(1.0);
    flat_src.t.push_back(i * 0.01), flat_src.v.push_back(2.0);
  }
  EXPECT_HAS(error_of([&] { (void)estimate_clock_offset(flat_bus, flat_src, {}, "src"); }),
             "src: too few parts of the run correlate");
  TimeSeries short_src{{0, 1, 2}, {0, 1, 0}};
  EXPECT_HAS(error_of([&] { (void)estimate_clock_offset(flat_bus, short_src, {}, "src"); }), "src: the source and the bus overlap for");
}

}  // namespace
}  // namespace dynid::car
