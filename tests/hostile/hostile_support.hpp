#pragma once
// Shared by the hostile-input tests (label hostile): the three programs run as child processes
// with a time limit (a hang fails the test instead of blocking it), their output captured, and
// the inputs they are fed made here: CAN logs with time jumps, FIFOs, directories, devices,
// numbers at and past their limits.
//
// DYNID_HOSTILE_BIN (environment): a folder holding dynid-car, dynid-server and dynid to run
// instead of this build's (e.g. a build of the code before a fix, to see the tests fail on it).
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <dynid/can/frame.hpp>

#include "car_test_support.hpp"

namespace dynid::hostile {

using namespace std::chrono_literals;
using car::test::ScratchDir;

enum class Program { Car, Server, Cli };
std::string program(Program p);

struct Outcome {
  std::optional<int> exit;  ///< nullopt: still running at the time limit (then killed)
  std::string output;       ///< stdout and stderr
  double seconds = 0.0;
};
/// Runs `program` with `args` in `scratch` (its output in a file there), killed after `limit`.
Outcome run(Program p, const std::vector<std::string>& args, const ScratchDir& scratch,
            std::chrono::milliseconds limit = 10s);
/// A program running for the length of a test, its output in `log`; killed (by its id) at the end.
class Running {
 public:
  Running(Program p, const std::vector<std::string>& args, const std::filesystem::path& log);
  ~Running();
  Running(const Running&) = delete;
  Running& operator=(const Running&) = delete;

 private:
  int pid_ = -1;
};

/// "exit 1 in 0.02 s: <output>" for a failure message.
std::string describe(const Outcome& o);

using car::test::source_dir;
std::filesystem::path loopback_xml();
std::filesystem::path testcar_profile();

/// The frames of deploy/scenarios/<scenario>.toml's CAN log (dynid-sim, made once per process).
const std::vector<can::Frame>& simulated_frames(const std::string& scenario = "sine_steer");
/// Writes frames as a candump -l log.
void write_log(const std::filesystem::path& file, const std::vector<can::Frame>& frames);
void write_text(const std::filesystem::path& file, const std::string& text);
std::string read_text(const std::filesystem::path& file);
/// A FIFO at `file` (nobody writes to it: a reader that opens it blocks).
void make_fifo(const std::filesystem::path& file);
/// Paths that are no regular file, with the word a refusal names them by: a FIFO and a folder
/// in `scratch`, /dev/null.
std::vector<std::pair<std::filesystem::path, std::string>> not_regular_files(const ScratchDir& scratch);

/// Numbers no numeric option takes: not finite, not numbers, absurd.
std::vector<std::string> hostile_numbers();

/// A numeric option and what it is given: `before` + {option, value} + `after`, for every value
/// of hostile_numbers() and `past` (values just past its limits).
struct NumericOption {
  std::string option;
  std::vector<std::string> past;
  std::vector<std::string> before;
  std::vector<std::string> after = {};
};
/// Each value must be refused: exit `status` within 5 s, the output naming the option, and
/// `untouched` (a file the program would write) not created.
void expect_refused(Program p, const NumericOption& o, int status, const ScratchDir& scratch,
                    const std::filesystem::path& untouched = {});

}  // namespace dynid::hostile
