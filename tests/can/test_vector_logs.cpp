// Vector ASC and BLF logs (issue 17): the readers against python-can (Debian's python3-can, the
// reference writer and reader, never our own code), their errors on bad files (line or byte
// offset named), and the format detection dynid-car --replay relies on.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include <dynid/can/asc.hpp>
#include <dynid/can/blf.hpp>
#include <dynid/can/candump.hpp>
#include <dynid/can/log_reader.hpp>
#include <dynid/error.hpp>

#include "can_test_support.hpp"
#include "temp_dir.hpp"

namespace dynid::can {
namespace {

using test::described;
using test::read_all;

using ::dynid::test::TempDir;

TEST(AscReader, ReadsClassicExtendedRemoteAndFdFramesWithTheMeasurementStart) {
  std::istringstream in(
      "date Thu Aug 02 10:30:00.000 AM 2018\n"
      "base hex  timestamps absolute\n"
      "internal events logged\n"
      "// version 9.0.0\n"
      "Begin Triggerblock Thu Aug 02 10:30:00.125 AM 2018\n"
      "   0.000000 Start of measurement\n"
      "   0.000013 1  B4              Rx   d 8 00 00 00 00 1D 0B 7A 5E\n"
      "   0.001000 2  18DAF110x       Tx   d 3 02 10 03  Length = 0 BitCount = 0\n"
      "   0.002000 1  123             Rx   r 2\n"
      "   0.003000 CANFD   1 Rx 456                                   1 0 a 12 00 01 02 03 04 05 06 07 08 09 0A 0B 0 0 1000 0 0 0 0 0\n"
      "   0.004000 1  Statistic: D 0 R 0 XD 0 XR 0 E 0 O 0 B 0.00%\n"
      "End TriggerBlock\n");
  AscReader r(in, "t.asc");
  const auto frames = read_all(r);
  ASSERT_EQ(frames.size(), 4u) << ::testing::PrintToString(described(r));
  EXPECT_EQ(r.error_count(), 0u);
  EXPECT_TRUE(r.start_known());
  // 2018-08-02T10:30:00.125Z = 1533205800.125 s
  EXPECT_EQ(frames[0].timestamp, 1533205800.125013);
  EXPECT_EQ(frames[0].interface_name(), "can0");
  EXPECT_EQ(frames[0].id, 0xB4u);
  EXPECT_EQ(frames[0].length, 8);
  EXPECT_EQ(frames[0].data[7], 0x5E);
  EXPECT_TRUE(frames[1].extended);
  EXPECT_EQ(frames[1].id, 0x18DAF110u);
  EXPECT_EQ(frames[1].interface_name(), "can1");
  EXPECT_EQ(frames[1].length, 3);
  EXPECT_TRUE(frames[2].rtr);
  EXPECT_EQ(frames[2].length, 2);
  EXPECT_TRUE(frames[3].fd);
  EXPECT_EQ(frames[3].fd_flags, Frame::kFdBrs);
  EXPECT_EQ(frames[3].length, 12);
  EXPECT_EQ(frames[3].data[11], 0x0B);
}

TEST(AscReader, RelativeTimestampsAndDecimalBase) {
  std::istringstream in(
      "base dec  timestamps relative\n"
      "Begin Triggerblock\n"
      "   0.500000 1  180             Rx   d 2 255 16\n"
      "   0.250000 1  180             Rx   d 2 0 1\n");
  AscReader r(in, "t.asc");
  const auto frames = read_all(r);
  ASSERT_EQ(frames.size(), 2u) << ::testing::PrintToString(described(r));
  EXPECT_FALSE(r.start_known());
  EXPECT_EQ(frames[0].id, 180u);
  EXPECT_EQ(frames[0].data[0], 255);
  EXPECT_EQ(frames[0].timestamp, 0.5);
  EXPECT_EQ(frames[1].timestamp, 0.75);
}

TEST(AscReader, BadLinesAreNamedByLineAndSkipped) {
  std::istringstream in(
      "base hex  timestamps absolute\n"
      "Begin Triggerblock Thu Aug 02 10:30:00.125 AM 2018\n"
      "   0.1 1  B4 Rx d 8 00 00\n"                 // 3: fewer bytes than the dlc
      "   0.2 1  ZZZ Rx d 1 00\n"                   // 4: bad id
      "this is prose\n"                             // 5
      "   0.3 1  ErrorFrame\n"                      // 6: error frame
      "   0.4 1  800 Rx d 1 00\n"                   // 7: 11-bit id out of range
      "   0.5 1  B4 Rx d 1 00\n");
  AscReader r(in, "bad.asc");
  const auto frames = read_all(r);
  ASSERT_EQ(frames.size(), 1u);
  const auto errors = described(r);
  ASSERT_EQ(errors.size(), 5u);
  EXPECT_NE(errors[0].find("bad.asc:3: frame has fewer data bytes"), std::string::npos) << errors[0];
  EXPECT_NE(errors[1].find("bad.asc:4: bad id"), std::string::npos) << errors[1];
  EXPECT_NE(errors[2].find("bad.asc:5: expected a header line"), std::string::npos) << errors[2];
  EXPECT_NE(errors[3].find("bad.asc:6: error frame"), std::string::npos) << errors[3];
  EXPECT_NE(errors[4].find("bad.asc:7: id '800' is out of range"), std::string::npos) << errors[4];
}

TEST(AscReader, ParsesTheDatesVectorAndPythonCanWrite) {
  EXPECT_EQ(parse_asc_date("Thu Jan 01 12:53:28.584 PM 1970"), 46408584000000LL);
  EXPECT_EQ(parse_asc_date("Thu Jan 01 12:00:00.000 AM 1970"), 0LL);
  EXPECT_EQ(parse_asc_date("Wed Sep 30 14:12:42.123 2020"), parse_asc_date("Wed Sep 30 02:12:42.123 pm 2020"));
  EXPECT_FALSE(parse_asc_date("yesterday at noon"));
  EXPECT_FALSE(parse_asc_date("Thu Jan 01 13:00:00.000 PM 1970"));
}

// A small BLF written here, byte by byte, for the hostile cases (the reference files come from
// python-can below).
std::string blf_with_one_frame(std::uint16_t method) {
  auto put16 = [](std::string& s, std::uint16_t v) { s.push_back(char(v & 0xFF)), s.push_back(char(v >> 8)); };
  auto put32 = [&](std::string& s, std::uint32_t v) { put16(s, std::uint16_t(v & 0xFFFF)), put16(s, std::uint16_t(v >> 16)); };
  auto put64 = [&](std::string& s, std::uint64_t v) { put32(s, std::uint32_t(v)), put32(s, std::uint32_t(v >> 32)); };
  std::string obj = "LOBJ";
  put16(obj, 32), put16(obj, 1), put32(obj, 48), put32(obj, 1);  // CAN_MESSAGE
  put32(obj, 2), put16(obj, 0), put16(obj, 0), put64(obj, 1500);  // 1 ns units
  put16(obj, 1), obj.push_back(0), obj.push_back(2), put32(obj, 0x123);
  obj += std::string("\xAB\xCD\0\0\0\0\0\0", 8);
  std::string c = "LOBJ";
  put16(c, 16), put16(c, 1), put32(c, 32 + std::uint32_t(obj.size())), put32(c, 10);
  put16(c, method), c += std::string(6, '\0'), put32(c, std::uint32_t(obj.size())), c += std::string(4, '\0');
  std::string file = "LOGG";
  put32(file, 144);
  file += std::string(136, '\0');
  return file + c + obj;
}

TEST(BlfReader, ReadsAStoredContainerAndNamesOffsetsOfBadFiles) {
  {
    std::istringstream in(blf_with_one_frame(0));
    BlfReader r(in, "one.blf");
    const auto frames = read_all(r);
    ASSERT_EQ(frames.size(), 1u) << ::testing::PrintToString(described(r));
    EXPECT_EQ(frames[0].id, 0x123u);
    EXPECT_EQ(frames[0].length, 2);
    EXPECT_EQ(frames[0].timestamp, 1.5e-6);
    EXPECT_FALSE(r.start_known());
  }
  {  // truncated inside the frame object
    const std::string whole = blf_with_one_frame(0);
    std::istringstream in(whole.substr(0, whole.size() - 5));
    BlfReader r(in, "cut.blf");
    EXPECT_TRUE(read_all(r).empty());
    ASSERT_EQ(r.error_count(), 1u);
    EXPECT_EQ(described(r)[0], "cut.blf: offset 144: file ends inside an object of 80 bytes");
  }
  {  // "zlib" container that is not zlib
    std::istringstream in(blf_with_one_frame(2));
    BlfReader r(in, "z.blf");
    EXPECT_TRUE(read_all(r).empty());
    ASSERT_EQ(r.error_count(), 1u);
    EXPECT_NE(described(r)[0].find("z.blf: offset 144: log container does not inflate"), std::string::npos)
        << described(r)[0];
  }
  {
    std::istringstream in("LOGX and then some more bytes, enough for a header of seventy-two bytes .....");
    BlfReader r(in, "x.blf");
    EXPECT_TRUE(read_all(r).empty());
    EXPECT_EQ(described(r).at(0), "x.blf: offset 0: not a BLF file (no 'LOGG' header)");
  }
}

TEST(LogFormat, DetectedFromTheContent) {
  TempDir dir;
  const auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir.path() / name, std::ios::binary) << text;
    return dir.path() / name;
  };
  EXPECT_EQ(detect_log_format(write("a.log", blf_with_one_frame(0))), LogFormat::Blf);
  EXPECT_EQ(detect_log_format(write("b.log", "\ndate Thu Aug 02 10:30:00.000 AM 2018\n")), LogFormat::Asc);
  EXPECT_EQ(detect_log_format(write("c.asc", "(1.0) can0 123#00\n")), LogFormat::Candump);
  EXPECT_EQ(open_log(dir.path() / "a.log")->format(), LogFormat::Blf);
  EXPECT_THROW(detect_log_format(dir.path()), InputError);  // a directory
}

// The reference: python-can writes the same messages as candump, ASC and BLF; every reader here
// must read the same frames from each (times within the formats' resolution: ASC and BLF hold
// the measurement start to the millisecond, python-can starts it at the first message).
TEST(VectorLogs, ReadTheFramesPythonCanWrote) {
  TempDir dir;
  const std::string script = R"PY(
import can, sys, os
out = sys.argv[1]
t0 = 1533205800.125  # 2018-08-02T10:30:00.125Z, a whole millisecond
ms = [
  can.Message(timestamp=t0, arbitration_id=0xB4, is_extended_id=False, data=bytes([0, 1, 2, 3, 4, 5, 6, 7]), channel="can0"),
  can.Message(timestamp=t0 + 0.000013, arbitration_id=0x18DAF110, is_extended_id=True, data=b"\x02\x10\x03", channel="can1"),
  can.Message(timestamp=t0 + 0.001, arbitration_id=0x123, is_extended_id=False, is_remote_frame=True, dlc=2, channel="can0"),
  can.Message(timestamp=t0 + 0.5, arbitration_id=0x456, is_extended_id=False, is_fd=True, bitrate_switch=True, data=bytes(range(12)), channel="can0"),
  can.Message(timestamp=t0 + 1.25, arbitration_id=0x7FF, is_extended_id=False, data=b"", channel="can0"),
]
for ext in ("log", "asc", "blf"):
    with can.Logger(os.path.join(out, "ref." + ext)) as w:
        for m in ms:
            w.on_message_received(m)
)PY";
  std::ofstream(dir.path() / "write.py") << script;
  int status = -1;
  const std::string output = test::run_command("TZ=UTC " + std::string(DYNID_SYSTEM_PYTHON) + " " +
                                                   (dir.path() / "write.py").string() + " " + dir.path().string() + " 2>&1",
                                               status);
  ASSERT_EQ(status, 0) << "python-can (Debian's python3-can, installed by deploy/setup.sh) failed:\n" << output;
  CandumpReader reference(dir.path() / "ref.log");
  const auto expected = read_all(reference);
  ASSERT_EQ(expected.size(), 5u);
  for (const char* ext : {"asc", "blf"}) {
    SCOPED_TRACE(ext);
    const auto reader = open_log(dir.path() / (std::string("ref.") + ext));
    EXPECT_EQ(reader->format(), std::string(ext) == "asc" ? LogFormat::Asc : LogFormat::Blf);
    const auto got = read_all(*reader);
    EXPECT_EQ(reader->error_count(), 0u) << ::testing::PrintToString(described(*reader));
    ASSERT_EQ(got.size(), expected.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
      SCOPED_TRACE(i);
      EXPECT_NEAR(got[i].timestamp, expected[i].timestamp, 1e-6);
      EXPECT_EQ(got[i].interface_name(), expected[i].interface_name());
      EXPECT_EQ(got[i].id, expected[i].id);
      EXPECT_EQ(got[i].extended, expected[i].extended);
      EXPECT_EQ(got[i].rtr, expected[i].rtr);
      EXPECT_EQ(got[i].fd, expected[i].fd);
      EXPECT_EQ(got[i].fd_flags, expected[i].fd_flags);
      // python-can's candump writer drops a remote frame's DLC ("#R"); ASC and BLF keep it (2).
      EXPECT_EQ(got[i].length, expected[i].rtr ? 2 : expected[i].length);
      EXPECT_EQ(std::memcmp(got[i].data.data(), expected[i].data.data(), got[i].length), 0);
    }
  }
}

}  // namespace
}  // namespace dynid::can
