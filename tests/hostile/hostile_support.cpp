#include "hostile_support.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <dynid/can/candump.hpp>

extern char** environ;

namespace dynid::hostile {
namespace {

pid_t spawn(const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("posix_spawn " + args[0] + ": " + std::strerror(rc));
  return pid;
}

// One child, waited for at most `limit`, killed (by its id) past it.
std::optional<int> spawn_and_wait(const std::vector<std::string>& args, const std::filesystem::path& log,
                                  std::chrono::milliseconds limit) {
  const pid_t pid = spawn(args, log);
  const auto deadline = std::chrono::steady_clock::now() + limit;
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) != pid) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return std::nullopt;
    }
    std::this_thread::sleep_for(5ms);
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

std::string program(Program p) {
  const char* name = p == Program::Car ? "dynid-car" : p == Program::Server ? "dynid-server" : "dynid";
  if (const char* dir = std::getenv("DYNID_HOSTILE_BIN")) return (std::filesystem::path(dir) / name).string();
  return p == Program::Car ? DYNID_CAR : p == Program::Server ? DYNID_SERVER : DYNID_CLI;
}

Outcome run(Program p, const std::vector<std::string>& args, const ScratchDir& scratch,
            std::chrono::milliseconds limit) {
  std::vector<std::string> argv{program(p)};
  argv.insert(argv.end(), args.begin(), args.end());
  const auto log = scratch.path() / "output.log";
  const auto start = std::chrono::steady_clock::now();
  Outcome o;
  o.exit = spawn_and_wait(argv, log, limit);
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.output = read_text(log);
  return o;
}

Running::Running(Program p, const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<std::string> argv{program(p)};
  argv.insert(argv.end(), args.begin(), args.end());
  pid_ = spawn(argv, log);
}

Running::~Running() {
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
}

std::string describe(const Outcome& o) {
  std::ostringstream s;
  s << (o.exit ? "exit " + std::to_string(*o.exit) : std::string("still running (killed)")) << " in " << o.seconds
    << " s: " << o.output.substr(0, 2000);
  return s.str();
}

std::filesystem::path loopback_xml() { return source_dir() / "deploy" / "cyclonedds" / "loopback.xml"; }
std::filesystem::path testcar_profile() { return car::test::profile_path("testcar.toml"); }

const std::vector<can::Frame>& simulated_frames(const std::string& scenario) {
  static ScratchDir scratch("hostile-sim");
  static std::map<std::string, std::vector<can::Frame>> cache;
  auto& frames = cache[scenario];
  if (!frames.empty()) return frames;
  const auto out = scratch.path() / scenario;
  const auto status = spawn_and_wait({DYNID_SIM, "--scenario",
                                      (source_dir() / "deploy" / "scenarios" / (scenario + ".toml")).string(), "--out",
                                      out.string()},
                                     scratch.path() / (scenario + ".log"), 60s);
  if (status != 0) throw std::runtime_error("dynid-sim " + scenario + ": " + read_text(scratch.path() / (scenario + ".log")));
  can::CandumpReader reader(out / "can.log", can::OnError::Stop);
  for (can::Frame f; reader.next(f);) frames.push_back(f);
  if (frames.empty() || reader.stopped()) throw std::runtime_error("dynid-sim " + scenario + ": no readable log");
  return frames;
}

void write_log(const std::filesystem::path& file, const std::vector<can::Frame>& frames) {
  std::ofstream out(file, std::ios::binary);
  can::CandumpWriter writer(out);
  for (const auto& f : frames) writer.write(f);
  if (!out.flush()) throw std::runtime_error("cannot write " + file.string());
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out.flush()) throw std::runtime_error("cannot write " + file.string());
}

void make_fifo(const std::filesystem::path& file) {
  if (mkfifo(file.c_str(), 0600) != 0) throw std::runtime_error("mkfifo " + file.string() + ": " + std::strerror(errno));
}

std::vector<std::pair<std::filesystem::path, std::string>> not_regular_files(const ScratchDir& scratch) {
  const auto fifo = scratch.path() / "fifo";
  if (!std::filesystem::exists(fifo)) make_fifo(fifo);
  const auto dir = scratch.path() / "dir";
  std::filesystem::create_directories(dir);
  return {{fifo, "FIFO"}, {dir, "directory"}, {"/dev/null", "character device"}};
}

std::vector<std::string> hostile_numbers() {
  return {"nan", "-nan", "inf", "-inf", "1e300", "-1e300", "-1", "abc", "", "0x", "1e", "99999999999999999999999"};
}

void expect_refused(Program p, const NumericOption& o, int status, const ScratchDir& scratch,
                    const std::filesystem::path& untouched) {
  auto values = hostile_numbers();
  values.insert(values.end(), o.past.begin(), o.past.end());
  for (const auto& value : values) {
    SCOPED_TRACE(o.option + " '" + value + "'");
    auto args = o.before;
    args.insert(args.end(), {o.option, value});
    args.insert(args.end(), o.after.begin(), o.after.end());
    const Outcome outcome = run(p, args, scratch, 5s);
    EXPECT_EQ(outcome.exit, status) << describe(outcome);
    EXPECT_NE(outcome.output.find(o.option), std::string::npos) << describe(outcome);
    if (!untouched.empty()) {
      EXPECT_FALSE(std::filesystem::exists(untouched));
    }
  }
}

}  // namespace dynid::hostile
