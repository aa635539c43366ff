// Bad input: every rejection names where and why, and nothing crashes.
#include <gtest/gtest.h>

#include <dynid/can/candump.hpp>
#include <dynid/can/dbc.hpp>
#include <dynid/can/decoder.hpp>
#include <dynid/can/encoder.hpp>
#include <dynid/error.hpp>
#include <random>
#include <sstream>

#include "can_test_support.hpp"

namespace dynid::can {
namespace {

using test::dbc_error;

// A problem confined to one message leaves the file readable and that message unusable: its
// problem, or "(usable)". The message is the last one of the file.
std::string message_problem(const std::string& text) {
  const Database db = parse_dbc_string(text, "bad.dbc");
  if (db.messages.empty()) return "(no message)";
  const Message& m = db.messages.back();
  return m.usable() ? "(usable)" : m.problem;
}

const std::string kGood = "BO_ 291 ENGINE: 8 ECU\n SG_ RPM : 0|16@1+ (0.25,0) [0|0] \"\" X\n";

TEST(BadDbc, SyntaxErrorsNameFileLineAndReason) {
  EXPECT_EQ(dbc_error("VERSION \"\"\nBO_ 291 ENGINE: 8 ECU\n SG_ SPEED : 0|16 1+ (1,0) [0|0] \"\" X\n"),
            "bad.dbc:3: SG_ 'SPEED': expected '@' after length, found '1'");
  EXPECT_EQ(dbc_error(kGood + " SG_ B : 0|8@2+ (1,0) [0|0] \"\" X\n"),
            "bad.dbc:3: SG_ 'B': expected byte order 0 (Motorola) or 1 (Intel) after '@', "
            "found '2'");
  EXPECT_EQ(dbc_error(kGood + " SG_ B : 0|8@1+ (1,0 [0|0] \"\" X\n"),
            "bad.dbc:3: SG_ 'B': expected ')' after offset, found '['");
  EXPECT_EQ(dbc_error(" SG_ A : 0|8@1+ (1,0) [0|0] \"\" X\n"),
            "bad.dbc:1: SG_: signal outside a message (no BO_ before it)");
  EXPECT_EQ(dbc_error("CM_ \"never closed;\n\n"),
            "bad.dbc:1: unterminated string (opening quote has no closing quote)");
  EXPECT_EQ(dbc_error(kGood + "BA_DEF_ BO_ \"X\" WORD;\n"),
            "bad.dbc:3: BA_DEF_ 'X': unknown attribute type 'WORD'");
  EXPECT_EQ(dbc_error(kGood + "CM_ BO_ 291 \"x\" junk;\n"),
            "bad.dbc:3: CM_: expected ';' at the end of the statement, found 'junk'");
  EXPECT_EQ(dbc_error(kGood + "} oops\n"), "bad.dbc:3: }: expected a section keyword, found '}'");
}

// Layout errors are confined to their message: the file loads, the message is unusable and
// keeps the error (tests/can/test_dbc_wild.cpp has the warnings and the lookups).
TEST(BadDbc, LayoutErrorsNameTheSignal) {
  EXPECT_EQ(message_problem(kGood + " SG_ L : 0|65@1+ (1,0) [0|0] \"\" X\n"),
            "bad.dbc:3: SG_ 'L': length 65 is outside 1..64 bits");
  EXPECT_EQ(message_problem(kGood + " SG_ L : 510|8@1+ (1,0) [0|0] \"\" X\n"),
            "bad.dbc:3: SG_ 'L': bits run past byte 64 (start 510, length 8)");
  EXPECT_EQ(message_problem(kGood + " SG_ RPM : 16|8@1+ (1,0) [0|0] \"\" X\n"),
            "bad.dbc:3: SG_ 'RPM': duplicate signal name in message 'ENGINE': line 2 has it too, "
            "and both can be in one frame");
  EXPECT_EQ(
      message_problem(kGood + " SG_ F : 16|16@1+ (1,0) [0|0] \"\" X\nSIG_VALTYPE_ 291 F : 1;\n"),
      "bad.dbc:3: SG_ 'F': a float signal (SIG_VALTYPE_ 1) must be 32 bits long, not 16");
  EXPECT_EQ(message_problem(kGood + " SG_ M3 m3 : 16|8@1+ (1,0) [0|0] \"\" X\n"),
            "bad.dbc:3: SG_ 'M3': multiplexed (m3) but message 'ENGINE' has no switch signal (M)");
  EXPECT_EQ(message_problem("BO_ 1 A: 8 X\n SG_ S1 m1M : 0|4@1+ (1,0) [0|0] \"\" X\n"
                            " SG_ S2 m1M : 4|4@1+ (1,0) [0|0] \"\" X\n"
                            "SG_MUL_VAL_ 1 S1 S2 1-1;\nSG_MUL_VAL_ 1 S2 S1 1-1;\n"),
            "bad.dbc:2: SG_ 'S1': multiplexer switches form a cycle");
  EXPECT_EQ(message_problem("BO_ 1 A: 65 X\n"), "bad.dbc:1: BO_ 'A': size 65 exceeds 64 bytes");
  EXPECT_EQ(message_problem("BO_ 1 A: 8 X\nBO_ 1 B: 8 X\n"),
            "bad.dbc:2: BO_ 'B': id 1 is already used by message 'A' (line 1)");
  EXPECT_EQ(message_problem(kGood), "(usable)");
}

TEST(BadDbc, MissingFile) {
  EXPECT_THROW(parse_dbc_file("/nonexistent/x.dbc"), InputError);
}

// Random garbage and random truncations of a valid file: an InputError or a database, never
// a crash or another exception type.
TEST(BadDbc, GarbageNeverCrashes) {
  const std::string valid = kGood + " SG_ T : 23|8@0- (1,-40) [0|0] \"°C\" X\nCM_ BO_ 291 \"c\";\n"
                                    "BA_DEF_ BO_ \"A\" INT 0 1;\nVAL_ 291 T 1 \"x\";\n";
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    std::string text = valid.substr(0, rng() % (valid.size() + 1));
    if (i % 2 == 0 && !text.empty()) text[rng() % text.size()] = static_cast<char>(rng() % 128);
    try {
      parse_dbc_string(text, "fuzz.dbc");
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("fuzz.dbc:", 0), 0U) << e.what();
    }
  }
}

TEST(BadLog, LinesAreReportedAndSkipped) {
  std::istringstream in(
      "(1.0) can0 123#0011\n"
      "(1.1) can0 123#00112\n"         // 2: odd digits
      "(1.2) can0 12#00\n"             // 3: 2-digit id
      "(1.3 can0 123#00\n"             // 4: unclosed timestamp
      "\n"                             // blank: skipped silently
      "(1.4) can0 123#001122334455667788\n"  // 6: 9 bytes classic
      "(1.5) can0 800#00\n"            // 7: 11-bit id out of range
      "(1.6) can0 123##100112233445566778899\n"  // 8: FD length 10
      "(1.7) can0 123#0G\n"            // 9: bad hex
      "(1.8) can0\n"                   // 10: truncated
      "(1.9) can0 123#00 trailing\n"   // 11: trailing text
      "(2.0) can0 20000080#0000000000000000\n"  // 12: error frame
      "(2.1) can0 1FFFFFFF#01\n");
  CandumpReader reader(in, "bad.log");
  Frame f;
  std::vector<double> times;
  while (reader.next(f)) times.push_back(f.timestamp);
  EXPECT_EQ(times, (std::vector<double>{1.0, 2.1}));
  EXPECT_EQ(reader.error_count(), 10U);
  ASSERT_EQ(reader.errors().size(), 10U);
  const std::vector<std::size_t> lines{2, 3, 4, 6, 7, 8, 9, 10, 11, 12};
  for (std::size_t i = 0; i < lines.size(); ++i) EXPECT_EQ(reader.errors()[i].line, lines[i]);
  EXPECT_EQ(reader.describe(reader.errors()[0]),
            "bad.log:2: bad hex data at '2' (bytes are two hex digits)");
  EXPECT_EQ(reader.errors()[1].reason,
            "the id must have 3 (standard) or 8 (extended) hex digits, found '12'");
  EXPECT_EQ(reader.errors()[3].reason,
            "payload longer than 8 bytes (classic CAN; CAN FD uses '##')");
  EXPECT_EQ(reader.errors()[5].reason, "CAN FD payload of 10 bytes is not a valid FD length");
  EXPECT_EQ(reader.errors()[7].reason, "missing frame after the interface name");
  EXPECT_EQ(reader.errors()[9].reason, "error frame (CAN_ERR_FLAG) '20000080'");
}

TEST(BadLog, StopOnFirstError) {
  std::istringstream in("(1.0) can0 123#00\nrubbish\n(2.0) can0 123#00\n");
  CandumpReader reader(in, "stop.log", OnError::Stop);
  Frame f;
  EXPECT_TRUE(reader.next(f));
  EXPECT_FALSE(reader.next(f));
  EXPECT_TRUE(reader.stopped());
  EXPECT_EQ(reader.describe(reader.errors().at(0)),
            "stop.log:2: expected a timestamp in parentheses, found 'rubbish'");
  EXPECT_FALSE(reader.next(f));
}

TEST(BadLog, MissingFile) { EXPECT_THROW(CandumpReader("/nonexistent/x.log"), InputError); }

TEST(BadFrames, UnknownIdShortPayloadAndPaddingAreCounted) {
  const Database db = parse_dbc_string(
      "BO_ 291 FIVE: 5 ECU\n SG_ X : 32|8@1+ (1,0) [0|0] \"\" X\n", "five.dbc");
  Decoder decoder(db);
  std::vector<DecodedSignal> out;
  Frame f;
  f.set_interface_name("can0");
  f.id = 0x124;
  f.length = 8;
  EXPECT_EQ(decoder.decode(f, out).status, DecodeStatus::UnknownId);
  f.id = 0x123;
  f.extended = true;  // same number, other kind of id
  EXPECT_EQ(decoder.decode(f, out).status, DecodeStatus::UnknownId);
  f.extended = false;
  f.length = 4;
  const DecodeResult short_result = decoder.decode(f, out);
  EXPECT_EQ(short_result.status, DecodeStatus::ShortPayload);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(explain(f, short_result),
            "frame 0x123 on 'can0' at t=0: payload too short: payload has 4 bytes, message "
            "'FIVE' needs 5");
  f.length = 8;  // padded like the RAV4 log
  f.data[4] = 7;
  const DecodeResult padded = decoder.decode(f, out);
  EXPECT_EQ(padded.status, DecodeStatus::Ok);
  EXPECT_TRUE(padded.length_mismatch);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].value, 7.0);
  f.rtr = true;
  EXPECT_EQ(decoder.decode(f, out).status, DecodeStatus::RemoteFrame);
  const DecodeStats& s = decoder.stats();
  EXPECT_EQ(s.frames, 5U);
  EXPECT_EQ(s.unknown_id, 2U);
  EXPECT_EQ(s.short_payload, 1U);
  EXPECT_EQ(s.decoded, 1U);
  EXPECT_EQ(s.length_mismatch, 1U);
  EXPECT_EQ(s.remote, 1U);
}

TEST(BadFrames, EncoderRejectsUnknownSignalAndNonFiniteValues) {
  const Database db = parse_dbc_string(kGood, "good.dbc");
  const Message& m = db.messages.at(0);
  Frame f;
  f.length = 3;
  const SignalValue unknown[] = {{"NOPE", 1.0}};
  try {
    encode_frame(m, unknown, f);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "message 'ENGINE': no signal 'NOPE'");
  }
  const SignalValue nan[] = {{"RPM", std::nan("")}};
  EXPECT_THROW(encode_frame(m, nan, f), InputError);
  EXPECT_EQ(f.length, 3);  // unchanged
}

}  // namespace
}  // namespace dynid::can
