// A corrupted store (label faults): a run is streamed through dynid-car into dynid-server and
// closed, the server stopped, the file copied (the operator's backup), then damaged on disk.
// (a) A b-tree page destroyed: PRAGMA quick_check finds it when the server opens the store; the
//     server refuses to start, naming the file and the damage, instead of serving anything.
// (b) Bytes inside a stored chunk changed (the page stays well-formed, so quick_check passes):
//     the server starts, but the chunk's CRC fails when a request needs it; the request fails
//     naming the file and the chunk, every time, and no estimate of the damaged run is served.
// In both cases the service resumes once the file is restored from the copy, with the same
// final estimates as before the damage.
#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <random>

#include "faults_fixture.hpp"

namespace dynid::faults {
namespace {

const std::string kRun = "intact";

// Overwrites bytes of a file in place.
void overwrite(const std::filesystem::path& file, std::uint64_t offset, const std::string& bytes) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(f.good()) << "cannot write " << file;
}

struct CorruptStore : ::testing::Test {
  CorruptStore() : scratch("faults-corrupt") {
    // One BLAS thread: the server then stops cleanly on SIGTERM (deploy/demo.sh says why).
    setenv("OPENBLAS_NUM_THREADS", "1", 1);
  }

  // Streams the log as kRun, closes it, stops the server; keeps a copy of the store and the
  // final estimates it recorded.
  void SetUp() override {
    log = simulated_run("sine_steer", scratch) / "can.log";
    ServerProcess server(store(), server_log(), 50);
    Child car(car_command(scratch.path() / "spool", kRun, log, 0.0), scratch.path() / "car.log");
    ASSERT_EQ(car.wait(90s), 0) << read_text(scratch.path() / "car.log");
    dynid_cli(scratch.path(), {"close", "--vehicle", kVehicle, "--run", kRun});
    ASSERT_EQ(server.stop(), 0) << read_text(server_log());
    ASSERT_FALSE(std::filesystem::exists(store().string() + "-wal")) << "a clean stop leaves no log";
    StoreReader reader(store());
    before = reader.final_estimates(kRun);
    ASSERT_FALSE(before.empty());
    std::filesystem::copy_file(store(), backup());
  }

  std::filesystem::path store() const { return scratch.path() / "store.db"; }
  std::filesystem::path backup() const { return scratch.path() / "store.db.copy"; }
  std::filesystem::path server_log() const { return scratch.path() / "server.log"; }

  // The operator's recovery: the damaged file moved aside, the copy put back; the server
  // started on it serves the run's final estimates as before.
  void restore_and_check() {
    std::filesystem::rename(store(), scratch.path() / "store.db.damaged");
    std::filesystem::copy_file(backup(), store());
    ServerProcess server(store(), server_log(), 50);
    dynid_cli(scratch.path(), {"close", "--vehicle", kVehicle, "--run", kRun});  // records them again
    ASSERT_EQ(server.stop(), 0) << read_text(server_log());
    StoreReader reader(store());
    EXPECT_EQ(reader.quick_check(), "ok");
    EXPECT_EQ(expect_same_estimates(reader.final_estimates(kRun), before, 0.0), 0.0);
  }

  ScratchDir scratch;
  std::filesystem::path log;
  std::map<std::string, std::string> before;
};

TEST_F(CorruptStore, DamagedPageStopsTheServerAtOpenNamingTheFileAndResumesFromACopy) {
  std::int64_t root = 0, page_size = 0;
  {
    StoreReader reader(store());
    root = reader.integer("SELECT rootpage FROM sqlite_schema WHERE name = 'chunks'");
    page_size = reader.integer("PRAGMA page_size");
  }
  ASSERT_GT(root, 1);
  // The root of the chunks b-tree, past its first bytes, replaced by random bytes (seeded).
  std::mt19937 random(7);
  std::string garbage(static_cast<std::size_t>(page_size) - 8, '\0');
  for (auto& c : garbage) c = static_cast<char>(random());
  overwrite(store(), static_cast<std::uint64_t>((root - 1) * page_size + 8), garbage);

  const auto offset = read_text(server_log()).size();
  ServerProcess damaged(store(), server_log(), 50);
  const auto status = damaged.child().wait(30s);
  const std::string said = text_since(server_log(), offset);
  EXPECT_EQ(status, 1) << "the server must refuse a damaged store: " << said;
  EXPECT_NE(said.find(store().string()), std::string::npos) << said;
  EXPECT_NE(said.find("quick_check failed"), std::string::npos) << said;
  std::cout << "the server said: " << said;

  restore_and_check();
}

TEST_F(CorruptStore, DamagedChunkBytesAreRefusedWhenReadNeverServedAndResumeFromACopy) {
  // A byte inside chunk #5's bytes, on one of its overflow pages: the page stays well formed.
  const auto chunk = ingest::encode_chunk(expected_chunks(log, kRun).at(5));
  const std::string file = read_text(store());
  std::size_t at = std::string::npos;
  for (std::size_t from = 2000; at == std::string::npos && from + 32 < chunk.size(); from += 97)
    at = file.find(chunk.substr(from, 32));
  ASSERT_NE(at, std::string::npos) << "chunk #5 not found in the file";
  overwrite(store(), at + 16, std::string(1, static_cast<char>(file[at + 16] ^ 0x5a)));
  {
    StoreReader reader(store());
    ASSERT_EQ(reader.quick_check(), "ok") << "this damage is meant to pass quick_check";
  }

  ServerProcess server(store(), server_log(), 50);
  const std::vector<std::string> estimates{DYNID_CLI, "--cyclone-config", loopback_options().config, "--domain",
                                           std::to_string(kDomain), "--timeout", "15", "estimates",
                                           "--vehicle", kVehicle, "--run", kRun};
  for (int attempt = 0; attempt < 2; ++attempt) {  // refused every time, not only the first
    const auto out = scratch.path() / "estimates.out";
    std::filesystem::remove(out);
    Child cli(estimates, out);
    const auto status = cli.wait(30s);
    const std::string said = read_text(out);
    EXPECT_NE(status, 0) << "estimates of a damaged run were served: " << said;
    EXPECT_NE(said.find(store().string()), std::string::npos) << said;
    EXPECT_NE(said.find(kVehicle + "/" + kRun + "#5"), std::string::npos) << said;
    EXPECT_NE(said.find("damaged"), std::string::npos) << said;
    if (attempt == 0) std::cout << "dynid estimates said: " << said;
  }
  ASSERT_EQ(server.stop(), 0) << read_text(server_log());

  restore_and_check();
}

}  // namespace
}  // namespace dynid::faults
