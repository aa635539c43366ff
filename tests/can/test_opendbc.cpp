// Every real DBC file of opendbc parses, and yields messages and signals.
#include <gtest/gtest.h>

#include <dynid/can/dbc.hpp>
#include <dynid/error.hpp>

#include "can_test_support.hpp"

namespace dynid::can {
namespace {

TEST(OpenDbc, AllFilesParse) {
  DYNID_REQUIRE_DIR(test::opendbc_dir());
  const auto files = test::opendbc_files();
  EXPECT_EQ(files.size(), 137U) << "the README of the shared data promises 137 DBC files (136 generated + psa_aee2010_r3)";
  std::size_t parsed = 0;
  for (const auto& path : files) {
    SCOPED_TRACE(path.filename().string());
    try {
      const Database db = parse_dbc_file(path);
      EXPECT_GT(db.messages.size(), 0U);
      EXPECT_GT(db.signal_count(), 0U);
      for (const Message& m : db.messages) {
        EXPECT_TRUE(m.usable()) << m.problem;
        if (m.is_pseudo) continue;
        EXPECT_EQ(db.find_message(m.id, m.extended), &m) << m.name;
      }
      ++parsed;
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_EQ(parsed, files.size());
}

}  // namespace
}  // namespace dynid::can
