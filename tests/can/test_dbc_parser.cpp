// The DBC sections real files use, on a hand-written file.
#include <gtest/gtest.h>

#include <dynid/can/dbc.hpp>

namespace dynid::can {
namespace {

// CRLF line ends, UTF-8 in a unit and a comment, escaped quotes in a multi-line comment.
std::string sample() {
  std::string text = R"(VERSION "1.2"

NS_ :
	NS_DESC_
	CM_
	BA_DEF_

BS_:

BU_: ECU GW

VAL_TABLE_ OnOff 1 "On" 0 "Off" ;

BO_ 291 ENGINE: 8 ECU
 SG_ RPM : 0|16@1+ (0.25,0) [0|16383.75] "1/min" GW,ECU
 SG_ TEMP : 23|8@0- (1,-40) [-40|215] "°C" GW

BO_ 2566914046 FD_MSG: 64 GW
 SG_ LAST : 504|8@1+ (1,0) [0|255] "" ECU

BO_TX_BU_ 291 : GW,ECU;

CM_ "network comment";
CM_ BU_ ECU "engine controller";
CM_ BO_ 291 "line one
line \"two\" ünïcode";
CM_ SG_ 291 RPM "engine speed";

BA_DEF_ BO_ "GenMsgCycleTime" INT 0 65535;
BA_DEF_ SG_ "GenSigStartValue" FLOAT 0 1e+09;
BA_DEF_ "BusType" STRING ;
BA_DEF_ BO_ "VFrameFormat" ENUM "StandardCAN","ExtendedCAN","StandardCAN_FD","ExtendedCAN_FD";
BA_DEF_DEF_ "GenMsgCycleTime" 100;
BA_DEF_DEF_ "VFrameFormat" "StandardCAN";
BA_ "BusType" "CAN FD";
BA_ "GenMsgCycleTime" BO_ 291 20;
BA_ "GenSigStartValue" SG_ 291 RPM 3;
BA_ "VFrameFormat" BO_ 2566914046 3;

EV_ EngineTemp : 1 [-40|215] "°C" 20 1 DUMMY_NODE_VECTOR0 ECU,GW;

VAL_ 291 TEMP 215 "overflow" -40 "underflow" ;
SIG_GROUP_ 291 Engine 1 : RPM TEMP;
BU_SG_REL_ something unknown "that is skipped";
)";
  std::string crlf;
  for (const char c : text) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  return crlf;
}

TEST(DbcParser, ReadsTheSectionsRealFilesUse) {
  const Database db = parse_dbc_string(sample(), "sample.dbc");
  EXPECT_EQ(db.version, "1.2");
  EXPECT_EQ(db.new_symbols, (std::vector<std::string>{"NS_DESC_", "CM_", "BA_DEF_"}));
  ASSERT_EQ(db.nodes.size(), 2U);
  EXPECT_EQ(db.nodes[0].comment, "engine controller");
  EXPECT_EQ(db.value_tables.at("OnOff").at(1), "On");
  EXPECT_EQ(db.comment, "network comment");
  EXPECT_TRUE(db.warnings.empty()) << db.warnings.front();

  ASSERT_NE(db.find_message(291, false), nullptr);
  const Message& engine = *db.find_message(291, false);
  EXPECT_EQ(engine.transmitter, "ECU");
  EXPECT_EQ(engine.extra_transmitters, (std::vector<std::string>{"GW", "ECU"}));
  EXPECT_EQ(engine.comment, "line one\nline \"two\" ünïcode");
  EXPECT_FALSE(engine.fd);
  const Signal& rpm = *engine.find_signal("RPM");
  EXPECT_EQ(rpm.byte_order, ByteOrder::Intel);
  EXPECT_DOUBLE_EQ(rpm.factor, 0.25);
  EXPECT_EQ(rpm.receivers, (std::vector<std::string>{"GW", "ECU"}));
  EXPECT_EQ(rpm.comment, "engine speed");
  const Signal& temp = *engine.find_signal("TEMP");
  EXPECT_EQ(temp.byte_order, ByteOrder::Motorola);
  EXPECT_TRUE(temp.is_signed);
  EXPECT_EQ(temp.unit, "°C");
  EXPECT_EQ(temp.value_descriptions.at(-40), "underflow");
  ASSERT_EQ(engine.signal_groups.size(), 1U);
  EXPECT_EQ(engine.signal_groups[0].signals, (std::vector<std::string>{"RPM", "TEMP"}));

  // Typed attribute values, own or default; ENUM resolved to its name.
  EXPECT_EQ(std::get<std::int64_t>(engine.attributes.at("GenMsgCycleTime")), 20);
  EXPECT_EQ(std::get<double>(rpm.attributes.at("GenSigStartValue")), 3.0);
  EXPECT_EQ(std::get<std::string>(db.network_attributes.at("BusType")), "CAN FD");
  EXPECT_EQ(std::get<std::string>(*attribute_value(db, engine.attributes, "VFrameFormat")),
            "StandardCAN");
  EXPECT_EQ(db.attribute_definitions.at("GenSigStartValue").maximum, 1e9);

  ASSERT_NE(db.find_message(0x18FFFFFE, true), nullptr);
  const Message& fd = *db.find_message(0x18FFFFFE, true);
  EXPECT_TRUE(fd.fd);  // VFrameFormat 3 = ExtendedCAN_FD
  EXPECT_EQ(fd.size, 64U);
  EXPECT_EQ(fd.required_bytes, 64U);
  EXPECT_EQ(db.find_message(0x18FFFFFE, false), nullptr);  // the extended flag matters

  ASSERT_EQ(db.environment_variables.size(), 1U);
  EXPECT_EQ(db.environment_variables[0].unit, "°C");
  EXPECT_EQ(db.environment_variables[0].access_nodes, (std::vector<std::string>{"ECU", "GW"}));
}

TEST(DbcParser, DanglingReferencesAreWarningsWithLine) {
  const Database db = parse_dbc_string("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\n"
                                       "CM_ SG_ 1 NOPE \"c\";\nVAL_ 99 S 1 \"x\";\n",
                                       "dangling.dbc");
  ASSERT_EQ(db.warnings.size(), 2U);
  EXPECT_EQ(db.warnings[0], "dangling.dbc:3: CM_: message 'A' has no signal 'NOPE'");
  EXPECT_EQ(db.warnings[1], "dangling.dbc:4: VAL_ 'S': message id 99 is not defined by a BO_");
}

}  // namespace
}  // namespace dynid::can
