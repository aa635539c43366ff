// A full filesystem (label faults): a real one, a small tmpfs (faults_fixture.hpp, SmallDisk)
// filled up while dynid-car streams a simulated run.
// (a) Under the server's store: the server reports the failure naming the store and the full
//     disk (log, and the store_errors counter of `dynid status`), acknowledges nothing it could
//     not store, keeps running; once there is room again the car's resends land and the final
//     estimates equal those of the same log delivered without trouble.
// (b) Under the car's spool: dynid-car reports the full disk, keeps what it had spooled and
//     holds what it cannot spool yet (nothing is sent before it is spooled); once there is room
//     the run completes, every chunk on the server once.
#include <gtest/gtest.h>

#include <regex>
#include <iostream>
#include <thread>

#include "faults_fixture.hpp"

namespace dynid::faults {
namespace {

constexpr std::uint64_t kDiskBytes = 24ULL << 20;

struct FullDisk : ::testing::Test {
  FullDisk() : scratch("faults-full-disk") { setenv("OPENBLAS_NUM_THREADS", "1", 1); }

  // Waits until `file` says `words` after `offset`; the text from offset on.
  std::string wait_for(const std::filesystem::path& file, std::size_t offset, const std::string& words,
                       std::chrono::milliseconds patience) {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    std::string said;
    while ((said = text_since(file, offset)).find(words) == std::string::npos &&
           std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(100ms);
    return said;
  }

  // The same log delivered without trouble as run "uninterrupted", both runs closed, the
  // server stopped; then the store must hold both runs once and the same final estimates.
  void expect_same_as_uninterrupted(std::unique_ptr<ServerProcess> server, const std::filesystem::path& store,
                                    const std::string& run, const std::filesystem::path& log) {
    Child reference(car_command(scratch.path() / "spool-ref", "uninterrupted", log, 0.0),
                    scratch.path() / "car-ref.log");
    ASSERT_EQ(reference.wait(90s), 0) << read_text(scratch.path() / "car-ref.log");
    dynid_cli(scratch.path(), {"close", "--vehicle", kVehicle, "--run", run});
    dynid_cli(scratch.path(), {"close", "--vehicle", kVehicle, "--run", "uninterrupted"});
    ASSERT_EQ(server->stop(), 0);
    StoreReader stored(store);
    EXPECT_EQ(stored.quick_check(), "ok");
    expect_stored_once(stored, run, expected_chunks(log, run));
    expect_stored_once(stored, "uninterrupted", expected_chunks(log, "uninterrupted"));
    const double worst =
        expect_same_estimates(stored.final_estimates(run), stored.final_estimates("uninterrupted"), 1e-9);
    std::cout << "final estimates: largest relative difference to the uninterrupted run " << worst << "\n";
  }

  ScratchDir scratch;
};

TEST_F(FullDisk, UnderTheStoreNothingUnstoredIsAcknowledgedAndTheRunCompletesWhenThereIsRoom) {
  const auto log = simulated_run("sine_steer", scratch) / "can.log";
  SmallDisk disk(scratch.path(), kDiskBytes);
  const auto store = disk.path() / "store.db";
  const auto server_log = scratch.path() / "server.log";
  const auto car_log = scratch.path() / "car.log";
  AckWatch acks;
  auto server = std::make_unique<ServerProcess>(store, server_log);
  Child car(car_command(scratch.path() / "spool", "full-store", log, 6.0), car_log);
  ASSERT_TRUE(acks.wait("full-store", 3, 30s)) << read_text(server_log) << read_text(car_log);

  const auto offset = read_text(server_log).size();
  std::cout << "filled the store's filesystem with " << disk.fill() << " bytes at #" << acks.highest() << "\n";
  const std::string said = wait_for(server_log, offset, "not stored", 30s);
  std::smatch failed;
  // "<n> chunks not stored (<vehicle>/<run>#<first>..): store <path>: ...": one group commit.
  ASSERT_TRUE(std::regex_search(said, failed, std::regex("not stored \\(" + kVehicle + "/full-store#([0-9]+)")))
      << said;
  const std::int64_t first_failed = std::stoll(failed[1]);
  std::cout << "the server said: " << said.substr(0, said.find('\n') + 1);
  EXPECT_NE(said.find(store.string()), std::string::npos) << said;
  EXPECT_TRUE(std::regex_search(said, std::regex("disk (is )?full"))) << said;  // SQLite: "database or disk is full"
  const std::string status = dynid_cli(scratch.path(), {"--json", "status"});
  EXPECT_EQ(status.find("\"store_errors\":0"), std::string::npos) << status;

  std::this_thread::sleep_for(2s);  // the car resends meanwhile; nothing may be acknowledged
  acks.take("full-store", 0ms);
  EXPECT_LT(acks.highest(), first_failed) << "a chunk that could not be stored was acknowledged";
  ASSERT_TRUE(server->child().running()) << read_text(server_log);
  ASSERT_TRUE(car.running()) << read_text(car_log);

  disk.make_room();
  ASSERT_EQ(car.wait(90s), 0) << read_text(car_log);
  expect_same_as_uninterrupted(std::move(server), store, "full-store", log);
}

TEST_F(FullDisk, UnderTheSpoolTheCarKeepsWhatItSpooledAndCompletesTheRunWhenThereIsRoom) {
  const auto log = simulated_run("sine_steer", scratch) / "can.log";
  SmallDisk disk(scratch.path(), kDiskBytes);
  const auto store = scratch.path() / "store.db";
  const auto car_log = scratch.path() / "car.log";
  AckWatch acks;
  auto server = std::make_unique<ServerProcess>(store, scratch.path() / "server.log");
  Child car(car_command(disk.path() / "spool", "full-spool", log, 6.0), car_log);
  ASSERT_TRUE(acks.wait("full-spool", 3, 30s)) << read_text(car_log);

  const auto offset = read_text(car_log).size();
  std::cout << "filled the spool's filesystem with " << disk.fill() << " bytes at #" << acks.highest() << "\n";
  const std::string said = wait_for(car_log, offset, "in memory until the spool can store them", 30s);
  std::cout << "dynid-car said: " << said;
  EXPECT_NE(said.find((disk.path() / "spool").string()), std::string::npos) << said;
  EXPECT_NE(said.find("disk full"), std::string::npos) << said;
  std::this_thread::sleep_for(2s);
  ASSERT_TRUE(car.running()) << "dynid-car gave up on a full disk: " << read_text(car_log);

  disk.make_room();
  ASSERT_EQ(car.wait(90s), 0) << read_text(car_log);
  expect_same_as_uninterrupted(std::move(server), store, "full-spool", log);
}

}  // namespace
}  // namespace dynid::faults
