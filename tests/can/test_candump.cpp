// candump log lines: parsing, writing, and canplayer's tools accepting what we write.
#include <gtest/gtest.h>
#include <unistd.h>

#include <dynid/can/candump.hpp>
#include <dynid/error.hpp>
#include <fstream>
#include <sstream>

#include "can_test_support.hpp"

namespace dynid::can {
namespace {

Frame parse(std::string_view line) {
  Frame f;
  const std::string err = parse_candump_line(line, f);
  EXPECT_EQ(err, "") << line;
  return f;
}

TEST(Candump, ParsesClassicExtendedFdRemoteAndEmpty) {
  const Frame c = parse("(1533239032.123456) can0 1C4#0011223344556677");
  EXPECT_DOUBLE_EQ(c.timestamp, 1533239032.123456);
  EXPECT_EQ(c.interface_name(), "can0");
  EXPECT_EQ(c.id, 0x1C4U);
  EXPECT_FALSE(c.extended);
  EXPECT_EQ(c.length, 8);
  EXPECT_EQ(c.data[7], 0x77);

  const Frame e = parse("(0.5) vcan1 18DAF110#02.10.03");  // '.' separators are allowed
  EXPECT_TRUE(e.extended);
  EXPECT_EQ(e.id, 0x18DAF110U);
  EXPECT_EQ(e.length, 3);
  EXPECT_EQ(e.data[1], 0x10);

  const Frame fd = parse("(1.000001) can0 123##3" + std::string(24, 'A') + "\r");
  EXPECT_TRUE(fd.fd);
  EXPECT_EQ(fd.fd_flags, Frame::kFdBrs | Frame::kFdEsi);
  EXPECT_EQ(fd.length, 12);

  const Frame r = parse("(2.0) can0 123#R");
  EXPECT_TRUE(r.rtr);
  EXPECT_EQ(r.length, 0);
  EXPECT_EQ(parse("(2.0) can0 123#R4").length, 4);

  const Frame empty = parse("(3.0) can0 7FF#");
  EXPECT_EQ(empty.length, 0);
  EXPECT_EQ(empty.id, 0x7FFU);
}

TEST(Candump, WriterRoundTrips) {
  const char* const lines[] = {
      "(0046408.584930) can0 0AA#25B525B525A0258D",
      "(1533239032.000001) can1 18DAF110#0210",
      "(0000000001.500000) can0 123##1" "00112233445566778899AABBCCDDEEFF"
      "00112233445566778899AABBCCDDEEFF",
      "(0000000002.000000) vcan0 123#R",
      "(0000000003.000000) can0 7FF#",
  };
  for (const char* line : lines) {
    // Our own writer pads seconds to 10 digits like candump -l; compare after a parse.
    const Frame f = parse(line);
    const std::string written = format_candump_line(f);
    const Frame back = parse(written);
    EXPECT_EQ(format_candump_line(back), written);
    EXPECT_EQ(back.id, f.id);
    EXPECT_EQ(back.length, f.length);
    EXPECT_EQ(back.data, f.data);
    EXPECT_NEAR(back.timestamp, f.timestamp, 5e-7);
  }
  EXPECT_EQ(format_candump_line(parse("(1.5) can0 1C4#00FF")), "(0000000001.500000) can0 1C4#00FF");
}

TEST(Candump, WriterRejectsFramesItCannotWrite) {
  Frame f = parse("(1.0) can0 123#00");
  f.length = 9;
  EXPECT_THROW(format_candump_line(f), InputError);
  f = parse("(1.0) can0 123#00");
  f.timestamp = -1.0;
  EXPECT_THROW(format_candump_line(f), InputError);
  f = parse("(1.0) can0 123#00");
  f.id = 0x800;
  EXPECT_THROW(format_candump_line(f), InputError);
  // The reader takes any finite time; one whose microseconds overflow a 64-bit count was written
  // as "(-9223372036854.-775808)", a line nobody reads back (tests/fuzz/fuzz_candump).
  f = parse("(170000000046408.587693) can1 214#930C2C0900FC11FF");
  EXPECT_THROW(format_candump_line(f), InputError);
  f.timestamp = 9.1e12;
  EXPECT_EQ(format_candump_line(parse(format_candump_line(f))), format_candump_line(f));
}

// canplayer needs a CAN interface to send on; log2long (same package, same line parser as
// canplayer: can-utils' lib.c parse_canframe) reads the log without one.
TEST(Candump, CanUtilsAcceptsWhatWeWrite) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/log2long"))
      << "/usr/bin/log2long is absent: deploy/setup.sh installs can-utils";
  const auto path = std::filesystem::temp_directory_path() /
                    ("dynid_candump_" + std::to_string(getpid()) + ".log");
  {
    std::ofstream out(path);
    CandumpWriter w(out);
    w.write(parse("(1533239032.123456) can0 1C4#0011223344556677"));
    w.write(parse("(1533239032.200000) can0 18DAF110#0210"));
    w.write(parse("(1533239032.300000) can0 123##1" + std::string(128, 'B')));
    w.write(parse("(1533239032.400000) can0 321#R"));
  }
  int status = 0;
  const std::string out = test::run_command("/usr/bin/log2long < '" + path.string() + "'", status);
  std::filesystem::remove(path);
  ASSERT_EQ(status, 0);
  std::istringstream lines(out);
  std::string line;
  std::vector<std::string> got;
  while (std::getline(lines, line)) got.push_back(line);
  ASSERT_EQ(got.size(), 4U) << out;
  EXPECT_NE(got[0].find("1C4"), std::string::npos) << got[0];
  EXPECT_NE(got[0].find("00 11 22 33 44 55 66 77"), std::string::npos) << got[0];
  EXPECT_NE(got[1].find("18DAF110"), std::string::npos) << got[1];
  EXPECT_NE(got[2].find("[64]"), std::string::npos) << got[2];
  EXPECT_NE(got[3].find("remote request"), std::string::npos) << got[3];
}

}  // namespace
}  // namespace dynid::can
