#include "client_fixture.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <dynid/dds/conversions.hpp>
#include <dynid/dds/topics.hpp>

#include "dynid/car/candump_source.hpp"
#include "dynid/car/chunk_builder.hpp"
#include "dynid/car/pipeline.hpp"
#include "dynid/car/replay.hpp"
#include "dynid/car/vehicle_profile.hpp"

extern char** environ;

namespace dynid::car::testing {

std::filesystem::path source_dir() { return DYNID_SOURCE_DIR; }
std::filesystem::path loopback_xml() { return source_dir() / "deploy" / "cyclonedds" / "loopback.xml"; }

std::string process_tag() {
  static const std::string tag = "dynid-client-test-" + std::to_string(getpid()) + "-" +
                                 std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
  return tag;
}

dds::ParticipantOptions loopback_options(const std::string& tag) {
  return {kDomain, dds::config_file_uri(loopback_xml()) + ",<Discovery><Tag>" + tag + "</Tag></Discovery>"};
}

std::vector<ingest::Chunk> make_chunks(const std::string& vehicle, const std::string& run, std::size_t count,
                                       std::size_t rows) {
  std::vector<ingest::Chunk> out;
  ChunkBuilder builder(vehicle, run, 3, rows, [&](ingest::Chunk&& c) { out.push_back(std::move(c)); });
  for (std::uint64_t k = 0; k < rows * count; ++k) {
    const double v[3] = {static_cast<double>(k) / 3.0, 0.5 * static_cast<double>(k), -1.0};
    builder.add_row(k, v, k % 7 != 3);
  }
  return out;
}

ingest::RunAnnouncement make_announcement(const std::string& vehicle, const std::string& run) {
  ingest::RunAnnouncement a;
  a.vehicle = vehicle;
  a.run = run;
  a.sample_rate_hz = 100.0;
  a.channels = {{"vx", "m/s"}, {"ax", "m/s^2"}, {"wheel_torque", "N*m"}};
  a.models = {{"kinematic_longitudinal", {}, {}}};
  return a;
}

bool same_chunk(const ingest::Chunk& a, const ingest::Chunk& b) {
  return ingest::encode_chunk(a) == ingest::encode_chunk(b);
}

std::filesystem::path testcar_profile() { return source_dir() / "deploy" / "profiles" / "testcar.toml"; }

std::vector<ingest::Chunk> expected_chunks(const std::filesystem::path& log, const std::string& run,
                                           const std::filesystem::path& profile_file) {
  const auto profile = load_vehicle_profile(profile_file);
  std::vector<ingest::Chunk> out;
  CarPipeline pipeline(profile, run, [&](ingest::Chunk&& c) { out.push_back(std::move(c)); });
  CandumpSource source(log);
  replay(source, pipeline);
  return out;
}

TestAcker::TestAcker(const dds::Participant& participant, const std::string& vehicle)
    : vehicle_(vehicle),
      announcement_reader_(participant, {dds::vehicle_partition(vehicle)}),
      chunk_reader_(participant, {dds::vehicle_partition(vehicle)}),
      ack_writer_(participant, {dds::vehicle_partition(vehicle)}) {}

void TestAcker::poll(std::chrono::milliseconds wait) {
  const auto take_announcements = [&] {
    for (const auto& s : announcement_reader_.take()) {
      announcements.push_back(dds::from_wire(s.data));
      // As the server does: a receipt for an accepted announcement (nothing stored yet).
      if (!muted) acknowledge(announcements.back().run, contiguous(announcements.back().run));
    }
  };
  take_announcements();
  for (const auto& s : chunk_reader_.wait_take(wait)) received.push_back(dds::from_wire(s.data));
  take_announcements();
  if (muted) return;
  std::set<std::string> runs;
  for (const auto& c : received) runs.insert(c.run);
  for (const auto& run : runs) {
    const std::int64_t c = contiguous(run);
    auto it = acked_.find(run);
    if (c >= 0 && (it == acked_.end() || it->second < c)) acknowledge(run, c);
  }
}

void TestAcker::acknowledge(const std::string& run, std::int64_t through,
                            const std::vector<dds::ChunkRejection>& rejections) {
  dds::ChunkReceipt receipt{vehicle_, run, through, rejections};
  const auto sample = dds::to_wire(receipt);
  ack_writer_.write(sample.data);
  acked_[run] = through;
}

std::size_t TestAcker::distinct(const std::string& run) const {
  std::set<std::uint64_t> seen;
  for (const auto& c : received)
    if (c.run == run) seen.insert(c.sequence);
  return seen.size();
}

std::size_t TestAcker::copies(const std::string& run, std::uint64_t sequence) const {
  std::size_t n = 0;
  for (const auto& c : received) n += c.run == run && c.sequence == sequence;
  return n;
}

std::int64_t TestAcker::contiguous(const std::string& run) const {
  std::set<std::uint64_t> seen;
  for (const auto& c : received)
    if (c.run == run) seen.insert(c.sequence);
  std::int64_t through = -1;
  while (seen.count(static_cast<std::uint64_t>(through + 1))) ++through;
  return through;
}

Child::Child(const std::vector<std::string>& args, const std::filesystem::path& log) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  const int rc = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("posix_spawn " + args[0] + ": " + std::strerror(rc));
}

Child::~Child() {
  if (!reaped_ && pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, &status_, 0);
  }
}

std::optional<int> Child::wait(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!reaped_) {
    if (waitpid(pid_, &status_, WNOHANG) == pid_) {
      reaped_ = true;
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &status_, 0);
      reaped_ = true;
      return std::nullopt;
    }
    std::this_thread::sleep_for(20ms);
  }
  if (WIFEXITED(status_)) return WEXITSTATUS(status_);
  return 128 + WTERMSIG(status_);
}

void Child::signal(int sig) {
  if (!reaped_) kill(pid_, sig);
}

bool Child::running() {
  if (reaped_) return false;
  if (waitpid(pid_, &status_, WNOHANG) == pid_) reaped_ = true;
  return !reaped_;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::filesystem::path simulated_run(const std::string& scenario, const ScratchDir& scratch) {
  const auto out = scratch.path() / ("sim-" + scenario);
  if (std::filesystem::exists(out / "can.log")) return out;
  Child sim({DYNID_SIM, "--scenario", (source_dir() / "deploy" / "scenarios" / (scenario + ".toml")).string(),
             "--out", out.string()},
            scratch.path() / ("sim-" + scenario + ".log"));
  const auto status = sim.wait(60s);
  if (status != 0)
    throw std::runtime_error("dynid-sim " + scenario + " failed: " + read_text(scratch.path() / ("sim-" + scenario + ".log")));
  return out;
}

}  // namespace dynid::car::testing
