#pragma once
// Shared helpers of the CAN tests: where the reference data is, and skipping without it.
#include <filesystem>
#include <string>
#include <vector>

#include <dynid/can/log_reader.hpp>

namespace dynid::can::test {

std::filesystem::path shared_data();
std::filesystem::path opendbc_dir();
std::filesystem::path rav4_dir();

// Every *.dbc in opendbc/, sorted.
std::vector<std::filesystem::path> opendbc_files();

// The message of the InputError that parsing `text` as DBC file `name` throws, or "(no error)".
std::string dbc_error(const std::string& text, const std::string& name = "bad.dbc");

// Every frame the reader gives, to its end.
std::vector<Frame> read_all(LogReader& reader);

// The reader's kept errors as describe() says them.
std::vector<std::string> described(const LogReader& reader);

// Runs a shell command and returns its standard output; sets `status` to the exit code.
std::string run_command(const std::string& command, int& status);

}  // namespace dynid::can::test

// Skips the test with a clear message when a reference folder is absent.
#define DYNID_REQUIRE_DIR(dir)                                                            \
  do {                                                                                    \
    if (!std::filesystem::is_directory(dir))                                              \
      GTEST_SKIP() << "reference data folder " << (dir)                                   \
                   << " is absent (set -DDYNID_SHARED_DATA to the shared data folder)";   \
  } while (0)
