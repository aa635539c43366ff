// Bit layouts, float signals and extended multiplexing against hand-computed values, and the
// encode/decode round trip on real DBC files.
#include <gtest/gtest.h>

#include <cmath>
#include <dynid/can/dbc.hpp>
#include <dynid/can/decoder.hpp>
#include <dynid/can/encoder.hpp>
#include <dynid/can/signal_codec.hpp>
#include <map>
#include <random>
#include <set>

#include "can_test_support.hpp"

namespace dynid::can {
namespace {

Frame frame_of(const Message& m, std::initializer_list<std::uint8_t> bytes) {
  Frame f;
  f.id = m.id;
  f.extended = m.extended;
  f.length = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), f.data.begin());
  return f;
}

std::map<std::string, double> decode(const Database& db, const Frame& f) {
  Decoder d(db);
  std::vector<DecodedSignal> out;
  const DecodeResult r = d.decode(f, out);
  EXPECT_EQ(r.status, DecodeStatus::Ok) << explain(f, r);
  std::map<std::string, double> values;
  for (const DecodedSignal& s : out) values[s.signal->name] = s.value;
  return values;
}

const char* const kLayoutDbc = R"(VERSION ""
BU_: ECU
BO_ 100 LAYOUT: 8 ECU
 SG_ MOTO16 : 7|16@0+ (0.01,-67.67) [0|250] "km/h" XXX
 SG_ MOTO12S : 19|12@0- (1.5,0) [-500|500] "deg" XXX
 SG_ INTEL12 : 36|12@1+ (1,0) [0|4095] "" XXX
 SG_ INTEL8S : 56|8@1- (1,0) [-128|127] "" XXX
BO_ 2147483949 FLOATS: 16 ECU
 SG_ F32 : 0|32@1- (2,1) [0|0] "" XXX
 SG_ F64 : 71|64@0- (1,0) [0|0] "" XXX
SIG_VALTYPE_ 2147483949 F32 : 1;
SIG_VALTYPE_ 2147483949 F64 : 2;
)";

// Hand-computed: MOTO16 = 0x25B5 = 9653 -> 28.86 km/h; MOTO12S: byte 2 low nibble 0xF and
// byte 3 0xFF -> 0xFFF = -1 -> -1.5 deg; INTEL12 from bit 36: byte 4 high nibble 0xA, byte 5
// 0xCD -> 0xCDA = 3290; INTEL8S byte 7 0x80 = -128.
TEST(Codec, IntelAndMotorolaLayouts) {
  const Database db = parse_dbc_string(kLayoutDbc, "layout.dbc");
  const Message& m = *db.find_message(100, false);
  const auto v = decode(db, frame_of(m, {0x25, 0xB5, 0x0F, 0xFF, 0xA0, 0xCD, 0x00, 0x80}));
  EXPECT_NEAR(v.at("MOTO16"), 28.86, 1e-12);
  EXPECT_DOUBLE_EQ(v.at("MOTO12S"), -1.5);
  EXPECT_DOUBLE_EQ(v.at("INTEL12"), 3290.0);
  EXPECT_DOUBLE_EQ(v.at("INTEL8S"), -128.0);
  EXPECT_EQ(m.required_bytes, 8U);
}

// 1.5f is 0x3FC00000 (little endian 00 00 C0 3F), scaled: 1.5 * 2 + 1 = 4. -2.25 as a double
// is 0xC002000000000000, big endian from byte 8 (Motorola start bit 71 = MSB of byte 8).
TEST(Codec, FloatAndDoubleSignals) {
  const Database db = parse_dbc_string(kLayoutDbc, "layout.dbc");
  const Message& m = *db.find_message(301, true);
  EXPECT_TRUE(m.extended);
  EXPECT_TRUE(m.fd);  // 16 bytes
  EXPECT_EQ(m.signals[0].value_type, ValueType::Float32);
  EXPECT_EQ(m.signals[1].value_type, ValueType::Float64);
  const auto v = decode(db, frame_of(m, {0x00, 0x00, 0xC0, 0x3F, 0, 0, 0, 0, 0xC0, 0x02, 0, 0,
                                         0, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(v.at("F32"), 4.0);
  EXPECT_DOUBLE_EQ(v.at("F64"), -2.25);
  // Encoding writes the same bytes back.
  Frame f;
  const SignalValue values[] = {{"F32", 4.0}, {"F64", -2.25}};
  EXPECT_TRUE(encode_frame(m, values, f).ok());
  EXPECT_EQ(f.length, 16);
  EXPECT_EQ(f.data[2], 0xC0);
  EXPECT_EQ(f.data[3], 0x3F);
  EXPECT_EQ(f.data[8], 0xC0);
  EXPECT_EQ(f.data[9], 0x02);
}

// SW (M) selects SUB (m1M) for 1, A for 2..3 (SG_MUL_VAL_) and C for 0 (plain m0); SUB
// selects B for 5 and 7..9. PLAIN is always present.
const char* const kExtendedMuxDbc = R"(BO_ 2364540158 EXT_MUX: 8 ECU
 SG_ SW M : 0|4@1+ (1,0) [0|15] "" XXX
 SG_ SUB m1M : 4|4@1+ (1,0) [0|15] "" XXX
 SG_ A m2 : 8|8@1+ (1,0) [0|255] "" XXX
 SG_ B m5 : 8|16@1- (0.5,-1) [0|0] "" XXX
 SG_ C m0 : 24|8@1+ (1,0) [0|255] "" XXX
 SG_ PLAIN : 56|8@1+ (1,0) [0|255] "" XXX
SG_MUL_VAL_ 2364540158 SUB SW 1-1;
SG_MUL_VAL_ 2364540158 A SW 2-3;
SG_MUL_VAL_ 2364540158 B SUB 5-5, 7-9;
)";

using Values = std::map<std::string, double>;

TEST(Codec, ExtendedMultiplexing) {
  const Database db = parse_dbc_string(kExtendedMuxDbc, "extmux.dbc");
  const Message& m = *db.find_message(0x0CF004FE, true);
  // SW=1, SUB=8 -> B active: int16 0xFFFD = -3 -> -3 * 0.5 - 1 = -2.5.
  EXPECT_EQ(decode(db, frame_of(m, {0x81, 0xFD, 0xFF, 0xC8, 0, 0, 0, 42})),
            (Values{{"SW", 1}, {"SUB", 8}, {"B", -2.5}, {"PLAIN", 42}}));
  // SW=3 -> A (range 2-3); SUB is not selected, so neither is B.
  EXPECT_EQ(decode(db, frame_of(m, {0x83, 0x11, 0, 0xC8, 0, 0, 0, 42})),
            (Values{{"SW", 3}, {"A", 17}, {"PLAIN", 42}}));
  // SW=1, SUB=6 -> 6 is in no range of B.
  EXPECT_EQ(decode(db, frame_of(m, {0x61, 0x11, 0, 0xC8, 0, 0, 0, 42})),
            (Values{{"SW", 1}, {"SUB", 6}, {"PLAIN", 42}}));
  // SW=0 -> C, through the plain m0 indicator.
  EXPECT_EQ(decode(db, frame_of(m, {0x00, 0x11, 0, 0xC8, 0, 0, 0, 42})),
            (Values{{"SW", 0}, {"C", 200}, {"PLAIN", 42}}));
}

TEST(Codec, EncoderFollowsExtendedMultiplexing) {
  const Database db = parse_dbc_string(kExtendedMuxDbc, "extmux.dbc");
  const Message& m = *db.find_message(0x0CF004FE, true);
  Frame f;
  const SignalValue values[] = {{"B", -2.5}, {"SUB", 8}, {"SW", 1}, {"A", 5}, {"PLAIN", 42}};
  const EncodeReport report = encode_frame(m, values, f);
  EXPECT_EQ(report.inactive, std::vector<std::string>{"A"});  // SW=1 does not select A
  EXPECT_TRUE(report.clamped.empty());
  EXPECT_EQ(decode(db, f), (Values{{"SW", 1}, {"SUB", 8}, {"B", -2.5}, {"PLAIN", 42}}));
}

TEST(Codec, EncoderClampsAndReports) {
  const Database db = parse_dbc_string(kLayoutDbc, "layout.dbc");
  const Message& m = *db.find_message(100, false);
  Frame f;
  const SignalValue values[] = {{"INTEL8S", 1000.0}, {"INTEL12", -5.0}, {"MOTO16", 30.0}};
  const EncodeReport report = encode_frame(m, values, f);
  EXPECT_EQ(report.clamped, (std::vector<std::string>{"INTEL12", "INTEL8S"}));
  const auto v = decode(db, f);
  EXPECT_DOUBLE_EQ(v.at("INTEL8S"), 127.0);
  EXPECT_DOUBLE_EQ(v.at("INTEL12"), 0.0);
  EXPECT_NEAR(v.at("MOTO16"), 30.0, 1e-9);
}

// ---- round trip on real files ---------------------------------------------------------------

// A random raw integer k the signal can hold (exact in a double), its physical value
// k * factor + offset, nudged by less than half a step so that encoding must round.
struct Pick {
  double physical = 0.0;
  double nudged = 0.0;
};
Pick pick(const Signal& s, std::mt19937_64& rng) {
  const int bits = static_cast<int>(std::min<std::uint32_t>(s.length, 52));
  const double lo = s.is_signed ? -std::ldexp(1.0, bits - 1) : 0.0;
  const double hi = s.is_signed ? std::ldexp(1.0, bits - 1) - 1 : std::ldexp(1.0, bits) - 1;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double k = std::floor(lo + u(rng) * (hi - lo + 1));
  const double nudge = (u(rng) - 0.5) * 0.8;  // within +-0.4 of a step
  return {k * s.factor + s.offset, (k + nudge) * s.factor + s.offset};
}

// Signals active for switch value `choice` (simple multiplexing: the files used have no
// extended multiplexing).
bool active(const Signal& s, std::optional<std::uint64_t> choice) {
  return !s.is_multiplexed() || (choice && *s.mux_value == *choice);
}

std::size_t round_trip_message(const Database& db, const Message& m,
                               std::optional<std::uint64_t> choice, std::mt19937_64& rng) {
  std::vector<std::pair<std::string, Pick>> picks;
  std::vector<SignalValue> values;
  for (const Signal& s : m.signals) {
    if (!active(s, choice) || s.factor == 0.0) continue;
    Pick p = pick(s, rng);
    if (s.is_multiplexer && choice) p = {static_cast<double>(*choice) * s.factor + s.offset,
                                         static_cast<double>(*choice) * s.factor + s.offset};
    picks.emplace_back(s.name, p);
  }
  for (const auto& [name, p] : picks) values.push_back({name, p.nudged});
  Frame f;
  const EncodeReport report = encode_frame(m, values, f);
  EXPECT_TRUE(report.ok()) << m.name;
  const auto decoded = decode(db, f);
  for (const auto& [name, value] : decoded)  // the switch selected exactly what it should
    EXPECT_TRUE(active(*m.find_signal(name), choice)) << m.name << "." << name;
  for (const auto& [name, p] : picks) {
    const auto it = decoded.find(name);
    if (it == decoded.end()) {
      ADD_FAILURE() << m.name << "." << name << " not decoded back";
      continue;
    }
    EXPECT_NEAR(it->second, p.physical, 1e-9 * std::max(1.0, std::fabs(p.physical)))
        << m.name << "." << name << " encoded from " << p.nudged;
  }
  return picks.size();
}

// Two signals sharing bits (some real files define alternatives) cannot both round-trip.
bool has_overlap(const Message& m, std::optional<std::uint64_t> choice) {
  std::vector<std::uint8_t> used(64, 0);
  for (const Signal& s : m.signals) {
    if (!active(s, choice)) continue;
    std::array<std::uint8_t, 64> bits{};
    insert_raw(s, ~std::uint64_t{0}, bits);
    for (std::size_t i = 0; i < 64; ++i) {
      if ((used[i] & bits[i]) != 0) return true;
      used[i] = static_cast<std::uint8_t>(used[i] | bits[i]);
    }
  }
  return false;
}

TEST(Codec, RoundTripOnRealFiles) {
  DYNID_REQUIRE_DIR(test::opendbc_dir());
  std::mt19937_64 rng(7);
  std::size_t signals = 0;
  std::size_t skipped_overlap = 0;
  for (const char* file : {"toyota_nodsu_pt_generated.dbc", "vw_mqb_2010.dbc", "tesla_can.dbc",
                           "hyundai_kia_generic.dbc", "test.dbc", "FORD_CADS_64.dbc"}) {
    SCOPED_TRACE(file);
    const Database db = parse_dbc_file(test::opendbc_dir() / file);
    for (const Message& m : db.messages) {
      if (m.is_pseudo) continue;
      std::set<std::optional<std::uint64_t>> choices;
      for (const Signal& s : m.signals)
        if (s.is_multiplexed()) choices.insert(*s.mux_value);
      if (choices.empty()) choices.insert(std::nullopt);
      for (const auto& c : choices) {
        if (has_overlap(m, c)) {
          ++skipped_overlap;
          continue;
        }
        for (int rep = 0; rep < 3; ++rep) signals += round_trip_message(db, m, c, rng);
      }
    }
  }
  EXPECT_GT(signals, 10000U);
  std::cout << "round-tripped " << signals << " signal values (" << skipped_overlap
            << " message layouts with overlapping signals skipped)\n";
}

}  // namespace
}  // namespace dynid::can
