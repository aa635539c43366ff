// The input rules every program applies (label hostile, can, ingest), generated over their
// alphabets and sizes: the id rule (dynid/input/ids.hpp), input files (input_file.hpp), the
// candump reader's bound on a line (can/candump.hpp).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include <dynid/can/candump.hpp>
#include <dynid/error.hpp>
#include <dynid/input/ids.hpp>
#include <dynid/input/input_file.hpp>
#include <dynid/input/number.hpp>

#include "hostile_support.hpp"

namespace dynid::hostile {
namespace {

bool allowed(char c, bool first) {
  const bool alnum = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
  return alnum || (!first && (c == '.' || c == '_' || c == '-'));
}

// Every byte value, first and later, and every length around the bound.
TEST(HostileIds, EveryByteAndLengthIsJudgedByTheRuleAndShownEscaped) {
  for (int b = 0; b < 256; ++b) {
    const char c = static_cast<char>(b);
    for (const bool first : {true, false}) {
      const std::string id = first ? std::string(1, c) + "v" : "v" + std::string(1, c);
      SCOPED_TRACE(b);
      EXPECT_EQ(input::id_problem(id).empty(), allowed(c, first));
      if (allowed(c, first)) continue;
      try {
        input::check_vehicle_id(id);
        ADD_FAILURE() << "accepted";
      } catch (const InputError& e) {
        const std::string message = e.what();
        for (const char m : message) EXPECT_TRUE(m >= 0x20 && m < 0x7f) << "unescaped byte in " << message;
      }
    }
  }
  for (std::size_t n = 0; n <= 2 * input::kMaxIdLength; ++n)
    EXPECT_EQ(input::id_problem(std::string(n, 'v')).empty(), n >= 1 && n <= input::kMaxIdLength) << n;
  EXPECT_EQ(input::printable(std::string(1000, 'x')).size(), input::kMaxShown + 3);
  EXPECT_EQ(input::printable("a\nb'\\"), "a\\x0ab\\'\\\\");
}

TEST(HostileInputFiles, OnlyRegularFilesOfBoundedSizeAreRead) {
  ScratchDir scratch("hostile-input-files");
  const auto fifo = scratch.path() / "fifo";
  make_fifo(fifo);
  const auto sparse = scratch.path() / "sparse";
  { std::ofstream touch(sparse); }
  std::filesystem::resize_file(sparse, input::kMaxTextFileBytes + 1);
  const auto small = scratch.path() / "small";
  write_text(small, "text");
  for (const auto& [path, reason] : std::vector<std::pair<std::filesystem::path, std::string>>{
           {fifo, "is a FIFO (named pipe), not a regular file"},
           {scratch.path(), "is a directory, not a regular file"},
           {"/dev/zero", "is a character device, not a regular file"},
           {scratch.path() / "absent", "no such file"},
           {sparse, "more than the 67108864 accepted"}}) {
    SCOPED_TRACE(path.string());
    try {
      input::read_input_file(path, "thing");
      ADD_FAILURE() << "read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string() + ": thing: "), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(input::read_input_file(small, "thing"), "text");
}

// A line at every length around the bound is one bad line, however long (a junk line of
// megabytes once counted once per KiB and outvoted a log's frames); the good line after it is
// read. A file without newlines is read only as far as stop_after_bytes allows.
TEST(HostileCandump, ALongLineIsOneBadLineAndTheNextLineIsRead) {
  const std::size_t bound = can::CandumpReader::kMaxLineBytes;
  for (const std::size_t n :
       {bound - 2, bound - 1, bound, bound + 1, 3 * bound, 100 * bound + 7, 5000 * bound}) {
    SCOPED_TRACE(n);
    std::istringstream in(std::string(n, 'x') + "\n(1700000000.000001) can0 123#00\n");
    can::CandumpReader reader(in, "long.log");
    can::Frame f;
    ASSERT_TRUE(reader.next(f));
    EXPECT_EQ(f.id, 0x123u);
    EXPECT_EQ(reader.line_number(), 2u);
    ASSERT_EQ(reader.error_count(), 1u);
    EXPECT_EQ(reader.errors().front().line, 1u);
    if (n > bound) {
      EXPECT_EQ(reader.errors().front().reason,
                "line of " + std::to_string(n) + " bytes, longer than the " +
                    std::to_string(bound) + " a line may have: skipped");
    }
    EXPECT_FALSE(reader.next(f));
  }
  std::istringstream zeros(std::string(50 * bound, '\0'));
  can::CandumpReader reader(zeros, "zeros.log");
  reader.stop_after_bytes(10 * bound);
  can::Frame f;
  EXPECT_FALSE(reader.next(f));
  EXPECT_TRUE(reader.stopped());
  EXPECT_EQ(reader.error_count(), 1u);
  EXPECT_LE(reader.bytes_consumed(), 10 * bound + 1);
  EXPECT_NE(reader.errors().front().reason.find("reading stopped"), std::string::npos)
      << reader.errors().front().reason;
}

// Numbers in request arguments and effect names: the whole text is the number, finite, or none.
TEST(HostileNumbers, OnlyAWholeFiniteNumberIsANumber) {
  EXPECT_EQ(input::parse_finite("1457.5"), 1457.5);
  EXPECT_EQ(input::parse_finite("-80"), -80.0);
  EXPECT_EQ(input::parse_finite("1e-3"), 1e-3);
  EXPECT_EQ(input::parse_finite("1e300"), 1e300);  // finite: the caller bounds it
  for (const std::string bad : {"nan", "-nan", "inf", "-inf", "abc", "", "0x", "1e", " 1", "1 ", "1.5x", "1e400", "0x10",
                                "1,5", "+-1"})
    EXPECT_FALSE(input::parse_finite(bad)) << bad;
  EXPECT_EQ(input::parse_integer("10"), 10);
  EXPECT_EQ(input::parse_integer("-3"), -3);
  for (const std::string bad : {"", "1.0", "3 ", "99999999999999999999999", "nan", "0x1"})
    EXPECT_FALSE(input::parse_integer(bad)) << bad;
}

}  // namespace
}  // namespace dynid::hostile
