// The decoder against an independent one (canmatrix, Debian's python3-canmatrix) on random
// payloads for every message of a varied set of real opendbc files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <dynid/can/dbc.hpp>
#include <dynid/can/decoder.hpp>
#include <dynid/can/signal_codec.hpp>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "can_test_support.hpp"

namespace dynid::can {
namespace {

// Intel and Motorola, signed, multiplexed, 29-bit ids, CAN FD, CRLF and UTF-8 files, 64-bit
// signals (test.dbc), GM's and Ford's Vector-generated files.
const char* const kFiles[] = {
    "ESR.dbc",                              "FORD_CADS_64.dbc",
    "acura_ilx_2016_can_generated.dbc",     "bmw_e9x_e8x.dbc",
    "cadillac_ct6_chassis.dbc",             "chrysler_pacifica_2017_hybrid_generated.dbc",
    "fca_giorgio.dbc",                      "ford_lincoln_base_pt.dbc",
    "gm_global_a_high_voltage_management.dbc", "gm_global_a_powertrain_generated.dbc",
    "honda_civic_ex_2022_can_generated.dbc", "hyundai_canfd.dbc",
    "hyundai_kia_generic.dbc",              "mazda_3_2019.dbc",
    "mercedes_benz_e350_2010.dbc",          "nissan_leaf_2018_generated.dbc",
    "subaru_global_2017_generated.dbc",     "tesla_can.dbc",
    "tesla_radar_bosch_generated.dbc",      "test.dbc",
    "toyota_nodsu_pt_generated.dbc",        "volvo_v60_2015_pt.dbc",
    "vw_golf_mk4.dbc",                      "vw_mqb_2010.dbc",
};
constexpr int kRandomFramesPerMessage = 4;

// Signal values by frame index; a frame canmatrix does not know is absent.
using Reference = std::map<std::size_t, std::map<std::string, double>>;

// canmatrix (0.9.5) refuses a BO_ line whose id exceeds 11 bits without the extended flag
// (bit 31), printing e.g. "error with line no: 186 b'BO_ 13274 LKAS_HUD_A: 5 ADAS'" for
// honda_civic_ex_2022_can_generated.dbc, and then knows no such message. opendbc writes its
// 29-bit ids that way, and such a frame can only be a 29-bit one, which is what we decode.
// For these messages only, "unknown to canmatrix" is accepted instead of a comparison.
bool canmatrix_refuses(const Message& m) {
  return m.extended && (m.dbc_id & kDbcExtendedFlag) == 0;
}

// After refusing a BO_ line canmatrix keeps reading its SG_ lines into the message before it
// (RADAR_HUD then shows LKAS_HUD_A's signals in honda_civic_ex_2022_can_generated.dbc). The
// signals canmatrix wrongly adds to `message` (index in the file) are these.
std::set<std::string> wrongly_added_by_canmatrix(const Database& db, std::size_t message) {
  std::set<std::string> names;
  for (std::size_t k = message + 1; k < db.messages.size() && canmatrix_refuses(db.messages[k]);
       ++k)
    for (const Signal& s : db.messages[k].signals) names.insert(s.name);
  return names;
}

struct Job {
  std::vector<Frame> frames;
  std::vector<std::string> names;
};

// Random payloads; for a message with a switch, also one frame per declared switch value, so
// that multiplexed signals are exercised and not only the (mostly unused) random values.
Job make_frames(const Database& db, std::mt19937_64& rng) {
  Job job;
  for (const Message& m : db.messages) {
    // canmatrix needs the DBC size, so it cannot decode messages whose signals overflow it.
    if (m.is_pseudo || m.size == 0 || m.required_bytes > m.size) continue;
    std::vector<std::uint64_t> switch_values;
    const Signal* sw = nullptr;
    for (const Signal& s : m.signals)
      if (s.is_multiplexed()) {
        sw = &m.signals[static_cast<std::size_t>(s.multiplexer_index)];
        switch_values.push_back(*s.mux_value);
      }
    const std::size_t count = kRandomFramesPerMessage + switch_values.size();
    for (std::size_t k = 0; k < count; ++k) {
      Frame f;
      f.id = m.id;
      f.extended = m.extended;
      f.length = static_cast<std::uint8_t>(m.size);
      for (std::size_t b = 0; b < m.size; ++b) f.data[b] = static_cast<std::uint8_t>(rng());
      if (k >= kRandomFramesPerMessage)
        insert_raw(*sw, switch_values[k - kRandomFramesPerMessage], f.data);
      job.frames.push_back(f);
      job.names.push_back(m.name);
    }
  }
  return job;
}

std::string hex(const Frame& f) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string s;
  for (const std::uint8_t b : f.payload()) s += {kHex[b >> 4], kHex[b & 0xF]};
  return s;
}

Reference run_canmatrix(const std::filesystem::path& dbc, const Job& job) {
  const auto frames_path = std::filesystem::temp_directory_path() /
                           ("dynid_can_frames_" + std::to_string(getpid()) + ".txt");
  {
    std::ofstream out(frames_path);
    for (std::size_t i = 0; i < job.frames.size(); ++i)
      out << job.names[i] << ' ' << hex(job.frames[i]) << '\n';
  }
  int status = 0;
  const std::string cmd = std::string(DYNID_SYSTEM_PYTHON) + " " + DYNID_CAN_TEST_DIR +
                          "/canmatrix_decode.py '" + dbc.string() + "' '" +
                          frames_path.string() + "'";
  const std::string text = test::run_command(cmd, status);
  std::filesystem::remove(frames_path);
  EXPECT_EQ(status, 0) << cmd;
  Reference ref;
  std::istringstream in(text);
  std::size_t index = 0;
  std::string name;
  std::string value;
  while (in >> index >> name >> value) {
    if (name == "#") ref[index];  // decoded, perhaps without signals
    else if (name != "!") ref[index][name] = std::stod(value);  // "!": no such message
  }
  return ref;
}

bool close(double a, double b) { return std::fabs(a - b) <= 1e-9 * std::max(1.0, std::fabs(b)); }

struct Compared {
  std::size_t values = 0;
  std::size_t multiplexed = 0;  // of which signals selected by a switch
};

// Compares one file.
Compared compare_file(const std::filesystem::path& path, std::mt19937_64& rng) {
  const Database db = parse_dbc_file(path);
  const Job job = make_frames(db, rng);
  const Reference ref = run_canmatrix(path, job);
  Decoder decoder(db);
  std::vector<DecodedSignal> out;
  Compared compared;
  for (std::size_t i = 0; i < job.frames.size(); ++i) {
    const DecodeResult r = decoder.decode(job.frames[i], out);
    EXPECT_EQ(r.status, DecodeStatus::Ok) << job.names[i];
    const auto it = ref.find(i);
    if (it == ref.end()) {
      EXPECT_TRUE(r.message != nullptr && canmatrix_refuses(*r.message))
          << job.names[i] << ": canmatrix decoded nothing";
      continue;
    }
    const auto& expected = it->second;
    const auto extra = wrongly_added_by_canmatrix(
        db, static_cast<std::size_t>(r.message - db.messages.data()));
    std::set<std::string> ours;
    for (const DecodedSignal& d : out) ours.insert(d.signal->name);
    for (const auto& [name, value] : expected)
      EXPECT_TRUE(ours.count(name) != 0 || extra.count(name) != 0)
          << job.names[i] << "." << name << " decoded by canmatrix only";
    for (const DecodedSignal& d : out) {
      const auto e = expected.find(d.signal->name);
      if (e == expected.end()) {
        ADD_FAILURE() << job.names[i] << "." << d.signal->name << " not decoded by canmatrix";
        continue;
      }
      EXPECT_TRUE(close(d.value, e->second))
          << job.names[i] << "." << d.signal->name << " payload " << hex(job.frames[i])
          << ": ours " << d.value << ", canmatrix " << e->second;
      ++compared.values;
      compared.multiplexed += d.signal->is_multiplexed() ? 1 : 0;
    }
  }
  return compared;
}

TEST(Canmatrix, RandomPayloadsAgreeOnVariedOpendbcFiles) {
  DYNID_REQUIRE_DIR(test::opendbc_dir());
  ASSERT_TRUE(std::filesystem::exists(DYNID_SYSTEM_PYTHON))
      << DYNID_SYSTEM_PYTHON << " is absent: deploy/setup.sh installs python3-canmatrix";
  std::mt19937_64 rng(20240601);
  std::size_t files = 0;
  Compared total;
  for (const char* name : kFiles) {
    SCOPED_TRACE(name);
    const auto path = test::opendbc_dir() / name;
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    const Compared c = compare_file(path, rng);
    EXPECT_GT(c.values, 0U);
    total.values += c.values;
    total.multiplexed += c.multiplexed;
    ++files;
  }
  EXPECT_GE(files, 20U);
  EXPECT_GT(total.multiplexed, 100U) << "multiplexed signals were hardly exercised";
  std::cout << "compared " << total.values << " signal values (" << total.multiplexed
            << " multiplexed) in " << files << " files\n";
}

// The brief asks for psa_aee2010_r3.dbc (Peugeot 208); the shared data's README lists it. A copy
// of the data without it skips with the reason.
TEST(Canmatrix, PsaAee2010) {
  const auto path = test::opendbc_dir() / "psa_aee2010_r3.dbc";
  if (!std::filesystem::exists(path))
    GTEST_SKIP() << path << " is absent from the shared data (its README lists it)";
  std::mt19937_64 rng(208);
  EXPECT_GT(compare_file(path, rng).values, 0U);
}

}  // namespace
}  // namespace dynid::can
