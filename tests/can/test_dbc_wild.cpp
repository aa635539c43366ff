// DBC files as they are in the wild: '//' comments, old Mac line ends, names repeated under
// multiplexer values, and problems confined to one message that the file must survive.
#include <gtest/gtest.h>

#include <algorithm>
#include <dynid/can/dbc.hpp>
#include <dynid/can/decoder.hpp>
#include <dynid/can/encoder.hpp>
#include <dynid/error.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "can_test_support.hpp"

namespace dynid::can {
namespace {

std::filesystem::path strym_dir() {
  return std::filesystem::path(DYNID_CAN_TEST_DIR) / "data" / "strym";
}

std::string error_of(const std::string& text) {
  return test::dbc_error(text, "wild.dbc");
}

const Message& message(const Database& db, std::string_view name) {
  for (const Message& m : db.messages)
    if (m.name == name) return m;
  throw std::runtime_error("no message " + std::string(name));
}

bool has_warning(const Database& db, const std::string& text) {
  return std::find(db.warnings.begin(), db.warnings.end(), text) != db.warnings.end();
}

std::string all_warnings(const Database& db) {
  std::string out;
  for (const std::string& w : db.warnings) out += w + "\n";
  return out;
}

const std::string kEngine = "BO_ 291 ENGINE: 8 ECU\n SG_ RPM : 0|16@1+ (0.25,0) [0|0] \"\" X\n";

TEST(DbcWild, CommentLinesAndTrailingCommentsAreSkipped) {
  const Database db = parse_dbc_string(
      "// header comment\n"
      "VERSION \"\" // trailing\n"
      "BO_ 291 ENGINE: 8 ECU // trailing after a message\n"
      "// SG_ OLD : 0|8@1+ (1,0) [0|0] \"\" X\n"
      "  //SG_ INDENTED : 0|8@1+ (1,0) [0|0] \"\" X\n"
      " SG_ RPM : 0|16@1+ (0.25,0) [0|0] \"rpm\" X // trailing after a signal\n"
      "//BO_ 300 GONE: 8 ECU\n"
      "// SG_ GONE_TOO : 0|8@1+ (1,0) [0|0] \"\" X\n"
      "CM_ SG_ 291 RPM \"http://kept // as text\"; // trailing after ';'\n"
      "VAL_ 999 X 1 \"a\" ;\n",
      "wild.dbc");
  ASSERT_EQ(db.messages.size(), 1U);
  const Message& m = db.messages[0];
  ASSERT_EQ(m.signals.size(), 1U);
  EXPECT_EQ(m.signals[0].name, "RPM");
  EXPECT_EQ(m.signals[0].unit, "rpm");
  EXPECT_EQ(m.signals[0].line, 6U);
  EXPECT_EQ(m.signals[0].comment, "http://kept // as text");
  // Line numbers go on counting through comment lines.
  EXPECT_EQ(db.warnings, std::vector<std::string>{
                             "wild.dbc:10: VAL_ 'X': message id 999 is not defined by a BO_"});
  // A single '/' is no comment.
  EXPECT_EQ(error_of(kEngine + "/ x\n"), "wild.dbc:3: /: expected a section keyword, found '/'");
}

// The text of test_dbc_parser's sample with one line end replaced by another.
std::string with_line_ends(const std::string& text, const std::string& end) {
  std::string out;
  for (const char c : text) {
    if (c == '\n')
      out += end;
    else
      out += c;
  }
  return out;
}

TEST(DbcWild, OldMacLineEndsAreLineEnds) {
  const std::string text =
      "VERSION \"\"\n\nNS_ :\n\tCM_\n\tBA_\n\nBS_:\n\nBU_: ECU X\n\n" + kEngine +
      " SG_ TEMP : 23|8@0- (1,-40) [0|0] \"\" X\n\nCM_ BO_ 291 \"line one\nline two\";\n"
      "VAL_ 291 NOPE 1 \"x\" ;\n";
  const Database lf = parse_dbc_string(text, "wild.dbc");
  for (const std::string end : {"\r", "\r\n"}) {
    SCOPED_TRACE(end == "\r" ? "CR" : "CRLF");
    const Database db = parse_dbc_string(with_line_ends(text, end), "wild.dbc");
    ASSERT_EQ(db.messages.size(), 1U);
    EXPECT_EQ(db.messages[0].signals.size(), 2U);
    EXPECT_EQ(db.messages[0].line, lf.messages[0].line);
    EXPECT_EQ(db.messages[0].signals[1].line, 13U);
    EXPECT_EQ(db.messages[0].comment, "line one\nline two");
    EXPECT_EQ(db.nodes.size(), 2U);
    EXPECT_EQ(db.warnings, lf.warnings);
  }
  EXPECT_EQ(lf.warnings, std::vector<std::string>{
                             "wild.dbc:17: VAL_ 'NOPE': message 'ENGINE' has no signal 'NOPE'"});
  // An error names the line a CR-only file has it on.
  EXPECT_EQ(error_of(with_line_ends(kEngine + "\n SG_ B : 0|8@2+ (1,0) [0|0] \"\" X\n", "\r")),
            "wild.dbc:4: SG_ 'B': expected byte order 0 (Motorola) or 1 (Intel) after '@', found "
            "'2'");
}

TEST(DbcWild, AFileWithoutMessagesSaysSo) {
  const Database db = parse_dbc_string("VERSION \"\"\nNS_ :\n\tCM_\n", "empty.dbc");
  EXPECT_TRUE(db.messages.empty());
  EXPECT_EQ(db.warnings,
            std::vector<std::string>{"empty.dbc:4: the file defines no message (BO_)"});
}

// Toyota's radar: CHECKSUM under switch values 0 and 1, at the same place.
const std::string kRadar =
    "BO_ 401 TRACK_B_1: 8 XXX\n"
    " SG_ MUX M : 7|1@0+ (1,0) [0|0] \"\" XXX\n"
    " SG_ COUNTER m1 : 6|6@0+ (1,0) [0|255] \"\" XXX\n"
    " SG_ CHECKSUM m1 : 63|8@0+ (1,0) [0|255] \"\" XXX\n"
    " SG_ CHECKSUM m0 : 63|8@0+ (1,0) [0|255] \"\" XXX\n"
    " SG_ ANGLE m0 : 55|8@0- (0.5,0) [0|255] \"deg\" XXX\n"
    "CM_ SG_ 401 CHECKSUM \"both copies\";\n";

TEST(DbcWild, ANameRepeatedUnderOtherMultiplexerValuesLoadsAndIsAmbiguous) {
  const Database db = parse_dbc_string(kEngine + kRadar, "wild.dbc");
  const Message& m = message(db, "TRACK_B_1");
  EXPECT_TRUE(m.usable()) << m.problem;
  EXPECT_EQ(db.find_message(401, false), &m);
  EXPECT_EQ(db.warnings,
            std::vector<std::string>{
                "wild.dbc:6: SG_ 'CHECKSUM': 2 signals of message 'TRACK_B_1' have this name "
                "(lines 6, 7) under different multiplexer values: each decodes, but a profile "
                "cannot select the name"});
  ASSERT_EQ(m.ambiguous_signals.count("CHECKSUM"), 1U);
  EXPECT_EQ(m.ambiguous_signals.at("CHECKSUM"), (std::vector<std::size_t>{6, 7}));
  EXPECT_FALSE(m.signal_index("CHECKSUM"));
  EXPECT_EQ(m.find_signal("CHECKSUM"), nullptr);
  ASSERT_TRUE(m.signal_index("ANGLE"));
  EXPECT_EQ(m.signals[3].comment, "both copies");
  EXPECT_EQ(m.signals[2].comment, "both copies");

  // Each copy decodes when its value is selected.
  Decoder decoder(db);
  std::vector<DecodedSignal> out;
  Frame f;
  f.id = 401;
  f.length = 8;
  f.data[0] = 0x80 | 0x05;  // MUX 1, COUNTER 5
  f.data[7] = 0xAB;
  ASSERT_EQ(decoder.decode(f, out).status, DecodeStatus::Ok);
  std::vector<std::size_t> decoded;
  for (const DecodedSignal& d : out) decoded.push_back(d.index);
  std::sort(decoded.begin(), decoded.end());
  EXPECT_EQ(decoded, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(out.back().value, 0xAB);
  f.data[0] = 0;  // MUX 0
  ASSERT_EQ(decoder.decode(f, out).status, DecodeStatus::Ok);
  decoded.clear();
  for (const DecodedSignal& d : out) decoded.push_back(d.index);
  std::sort(decoded.begin(), decoded.end());
  EXPECT_EQ(decoded, (std::vector<std::size_t>{0, 3, 4}));

  const SignalValue checksum[] = {{"CHECKSUM", 1.0}};
  try {
    encode_frame(m, checksum, f);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "message 'TRACK_B_1': signal name 'CHECKSUM' is ambiguous (several SG_ of the "
                 "message have it)");
  }
}

TEST(DbcWild, ANameRepeatedWhereBothCanBeInOneFrameMakesTheMessageUnusable) {
  // Plain twice; plain and multiplexed; overlapping SG_MUL_VAL_ ranges of one switch.
  const std::string twins =
      "BO_ 500 TWICE: 8 X\n SG_ A : 0|8@1+ (1,0) [0|0] \"\" X\n"
      " SG_ A : 8|8@1+ (1,0) [0|0] \"\" X\n";
  const std::string mixed =
      "BO_ 501 MIXED: 8 X\n SG_ S M : 0|4@1+ (1,0) [0|0] \"\" X\n"
      " SG_ B : 8|8@1+ (1,0) [0|0] \"\" X\n"
      " SG_ B m1 : 16|8@1+ (1,0) [0|0] \"\" X\n";
  const std::string ranges =
      "BO_ 502 RANGES: 8 X\n SG_ S M : 0|4@1+ (1,0) [0|0] \"\" X\n"
      " SG_ C m1 : 8|8@1+ (1,0) [0|0] \"\" X\n"
      " SG_ C m2 : 16|8@1+ (1,0) [0|0] \"\" X\n"
      "SG_MUL_VAL_ 502 C S 1-3;\n";
  const Database db = parse_dbc_string(kEngine + twins + mixed + ranges, "wild.dbc");
  EXPECT_TRUE(message(db, "ENGINE").usable());
  EXPECT_EQ(message(db, "TWICE").problem,
            "wild.dbc:5: SG_ 'A': duplicate signal name in message 'TWICE': line 4 has it too, "
            "and both can be in one frame");
  EXPECT_EQ(message(db, "MIXED").problem,
            "wild.dbc:9: SG_ 'B': duplicate signal name in message 'MIXED': line 8 has it too, "
            "and both can be in one frame");
  EXPECT_EQ(message(db, "RANGES").problem,
            "wild.dbc:13: SG_ 'C': duplicate signal name in message 'RANGES': line 12 has it "
            "too, and both can be in one frame");
  for (const std::uint32_t id : {500U, 501U, 502U}) EXPECT_EQ(db.find_message(id, false), nullptr);
  EXPECT_NE(db.find_message(291, false), nullptr);
  EXPECT_TRUE(has_warning(db, message(db, "TWICE").problem +
                                  "; message 'TWICE' (line 3) is unusable: not decoded, and a "
                                  "profile cannot select it"))
      << all_warnings(db);
  EXPECT_EQ(db.warnings.size(), 3U) << all_warnings(db);
}

TEST(DbcWild, ALayoutErrorMakesOnlyItsMessageUnusable) {
  const Database db =
      parse_dbc_string(kEngine +
                           "BO_ 300 RADAR: 8 X\n SG_ FAR : 60|8@1+ (1,0) [0|0] \"\" X\n"
                           " SG_ L : 0|65@1+ (1,0) [0|0] \"\" X\n"
                           "BO_ 301 NEXT: 8 X\n SG_ N : 0|8@1+ (1,0) [0|0] \"\" X\n",
                       "wild.dbc");
  const Message& radar = message(db, "RADAR");
  EXPECT_FALSE(radar.usable());
  EXPECT_EQ(radar.problem, "wild.dbc:5: SG_ 'L': length 65 is outside 1..64 bits");
  EXPECT_EQ(db.warnings,
            std::vector<std::string>{
                "wild.dbc:5: SG_ 'L': length 65 is outside 1..64 bits; message 'RADAR' (line 3) "
                "is unusable: not decoded, and a profile cannot select it"});
  EXPECT_EQ(db.find_message(300, false), nullptr);  // its frames are unknown ids
  EXPECT_EQ(db.find_message("RADAR"), &radar);      // the name still finds it, to say why
  EXPECT_TRUE(message(db, "NEXT").usable());
  EXPECT_NE(db.find_message(301, false), nullptr);

  Frame f;
  const SignalValue far[] = {{"FAR", 1.0}};
  EXPECT_THROW(encode_frame(radar, far, f), InputError);
}

TEST(DbcWild, AnUnknownWordAmongTheSignalsMakesItsMessageUnusable) {
  const Database db =
      parse_dbc_string(kEngine +
                           "BO_ 300 RADAR: 8 X\n SG_ A : 0|8@1+ (1,0) [0|0] \"\" X\n"
                           " SGX_ B : 8|8@1+ (1,0) [0|0] \"\" X\n"
                           " SG_ C : 16|8@1+ (1,0) [0|0] \"\" X\n"
                           "CM_ BO_ 291 \"kept\";\nFOO bar 1 2\nbaz\n",
                       "wild.dbc");
  const Message& radar = message(db, "RADAR");
  EXPECT_EQ(radar.signals.size(), 2U);  // A and C
  EXPECT_EQ(radar.problem,
            "wild.dbc:5: SGX_: unknown section keyword among the signals of message 'RADAR' "
            "(line 5 skipped): a signal may be missing");
  EXPECT_EQ(message(db, "ENGINE").comment, "kept");
  EXPECT_TRUE(message(db, "ENGINE").usable());
  // Outside a message (here after a CM_) the unknown word is skipped with a warning only.
  EXPECT_TRUE(has_warning(db, "wild.dbc:8: FOO: unknown section keyword: lines 8-9 skipped"))
      << all_warnings(db);
  EXPECT_EQ(db.warnings.size(), 2U) << all_warnings(db);
}

TEST(DbcWild, TwoMessagesWithOneNameDecodeByIdButNotByName) {
  const Database db = parse_dbc_string(kEngine +
                                           "BO_ 292 ENGINE: 8 ECU\n"
                                           " SG_ TORQUE : 0|16@1+ (1,0) [0|0] \"\" X\n",
                                       "wild.dbc");
  EXPECT_EQ(db.warnings,
            std::vector<std::string>{
                "wild.dbc:3: BO_ 'ENGINE': name also used by the message at line 1 (id 0x123; "
                "this one: 0x124): both decode by id, a profile cannot select them by name"});
  EXPECT_EQ(db.find_message("ENGINE"), nullptr);
  ASSERT_EQ(db.find_messages("ENGINE").size(), 2U);
  EXPECT_EQ(db.find_messages("ENGINE")[1]->line, 3U);
  EXPECT_NE(db.find_message(291, false), nullptr);
  EXPECT_NE(db.find_message(292, false), nullptr);
}

TEST(DbcWild, TwoMessagesWithOneIdAreBothUnusable) {
  const Database db =
      parse_dbc_string(kEngine +
                           "BO_ 291 OTHER: 8 ECU\n SG_ T : 0|16@1+ (1,0) [0|0] \"\" X\n"
                           "BO_ 300 FINE: 8 ECU\n SG_ F : 0|16@1+ (1,0) [0|0] \"\" X\n",
                       "wild.dbc");
  EXPECT_EQ(message(db, "ENGINE").problem,
            "wild.dbc:1: BO_ 'ENGINE': id 291 is also used by message 'OTHER' (line 3)");
  EXPECT_EQ(message(db, "OTHER").problem,
            "wild.dbc:3: BO_ 'OTHER': id 291 is already used by message 'ENGINE' (line 1)");
  EXPECT_EQ(db.find_message(291, false), nullptr);
  EXPECT_NE(db.find_message(300, false), nullptr);
  EXPECT_EQ(db.warnings.size(), 2U) << all_warnings(db);
}

TEST(DbcWild, SizeAbove64BytesMakesOnlyItsMessageUnusable) {
  const Database db = parse_dbc_string(kEngine + "BO_ 1 A: 65 X\n", "wild.dbc");
  EXPECT_EQ(message(db, "A").problem, "wild.dbc:3: BO_ 'A': size 65 exceeds 64 bytes");
  EXPECT_TRUE(message(db, "ENGINE").usable());
}

TEST(DbcWild, NodesOnIndentedLinesAndAnIndentedBusSectionAfterNs) {
  const Database db =
      parse_dbc_string("NS_ :\n\tCM_\n\tBA_\n  BS_:\nBU_:\n\tNEO\n\tMCU\n" + kEngine, "wild.dbc");
  ASSERT_EQ(db.nodes.size(), 2U);
  EXPECT_EQ(db.nodes[1].name, "MCU");
  EXPECT_EQ(db.new_symbols, (std::vector<std::string>{"CM_", "BA_"}));
  EXPECT_TRUE(db.warnings.empty()) << all_warnings(db);
}

TEST(DbcWild, SyntaxErrorsStillRefuseTheFile) {
  EXPECT_EQ(error_of(kEngine + " SG_ B : 0|8@1+ (1,0 [0|0] \"\" X\n"),
            "wild.dbc:3: SG_ 'B': expected ')' after offset, found '['");
  EXPECT_EQ(error_of(kEngine + "} oops\n"), "wild.dbc:3: }: expected a section keyword, found '}'");
  // A mistyped BO_ loses its message: the signals after it say where.
  EXPECT_EQ(error_of("B0_ 427 msg1 : 48 XXX\n SG_ A : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            "wild.dbc:2: SG_: signal outside a message (no BO_ before it; line 1 starts with the "
            "unknown word 'B0_')");
}

TEST(DbcWild, StrymToyotaRav4LoadsWithItsRadarNamesAmbiguous) {
  const Database db = parse_dbc_file(strym_dir() / "toyota_rav4_2019.dbc");
  EXPECT_GT(db.messages.size(), 50U);
  for (const Message& m : db.messages) EXPECT_TRUE(m.usable()) << m.problem;
  const Message& track = message(db, "TRACK_B_1");
  EXPECT_EQ(track.ambiguous_signals.at("CHECKSUM"), (std::vector<std::size_t>{252, 254}));
  EXPECT_EQ(track.ambiguous_signals.at("COUNTER"), (std::vector<std::size_t>{249, 262}));
  EXPECT_TRUE(has_warning(db, "toyota_rav4_2019.dbc:787: CM_: missing ';' before end of file"))
      << all_warnings(db);
  // The GAS_PEDAL commented out at line 401 (id 581) is not there; the one at line 437 is.
  ASSERT_NE(db.find_message("GAS_PEDAL"), nullptr);
  EXPECT_EQ(db.find_message("GAS_PEDAL")->id, 705U);
  EXPECT_EQ(db.find_message(581, false), nullptr);
  ASSERT_NE(db.find_message("WHEEL_SPEEDS"), nullptr);
  EXPECT_TRUE(db.find_message("WHEEL_SPEEDS")->signal_index("WHEEL_SPEED_FL"));
}

TEST(DbcWild, StrymHondaPilotLoadsAndTheBrokenNissanIsRefused) {
  const Database honda = parse_dbc_file(strym_dir() / "honda_pilot_2017.dbc");
  EXPECT_GT(honda.messages.size(), 20U);
  for (const Message& m : honda.messages) EXPECT_TRUE(m.usable()) << m.problem;
  try {
    parse_dbc_file(strym_dir() / "nissan_rogue_experimental.dbc");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "nissan_rogue_experimental.dbc:40: SG_: signal outside a message (no BO_ before "
                 "it; line 39 starts with the unknown word 'B0_')");
  }
}

}  // namespace
}  // namespace dynid::can
