// dynid-car killed with SIGKILL in the middle of a run (label faults), while its spool holds
// chunks the server has not acknowledged (the server is down at that moment, so there are
// some), then started again on the same spool. The restarted car announces the run again and
// delivers what the spool holds; the server ends with every chunk the car had spooled, once,
// bit for bit, folded once, and final estimates equal to those of the same chunks processed
// without interruption. (A car that is down cannot read what the bus carries meanwhile: the
// run on the server is the part the car had spooled, complete, not the whole log.)
#include <gtest/gtest.h>

#include <thread>
#include <iostream>

#include "dynid/car/spool.hpp"
#include "faults_fixture.hpp"

namespace dynid::faults {
namespace {

TEST(FaultsClientKill, KilledCarRestartedOnItsSpoolDeliversEverythingOnce) {
  ScratchDir scratch("faults-car-kill");
  const auto log = simulated_run("sine_steer", scratch) / "can.log";
  const auto all = expected_chunks(log, "car-killed");
  setenv("OPENBLAS_NUM_THREADS", "1", 1);
  const auto store = scratch.path() / "store.db";
  const auto server_log = scratch.path() / "server.log";
  const auto spool = scratch.path() / "spool";
  const auto car_log = scratch.path() / "car.log";

  auto server = std::make_unique<ServerProcess>(store, server_log);
  Child car(car_command(spool, "car-killed", log, 4.0), car_log);  // ~10 s of reading
  std::this_thread::sleep_for(2500ms);
  std::string why;
  ASSERT_TRUE(server->kill(why)) << why << read_text(server_log);  // chunks now pile up in the spool
  std::this_thread::sleep_for(2500ms);
  ASSERT_TRUE(car.running()) << "the car ended before it was killed: " << read_text(car_log);
  car.signal(SIGKILL);
  ASSERT_EQ(car.wait(10s), 128 + SIGKILL);

  std::uint64_t spooled = 0, pending = 0;
  {
    car::Spool look(spool, 1ULL << 40);
    const auto entries = look.pending_entries();
    pending = entries.size();
    ASSERT_GE(pending, 3U) << "the kill was meant to leave unacknowledged chunks in the spool";
    spooled = entries.back().sequence + 1;
  }
  std::cout << "car killed with " << pending << " chunks unacknowledged in its spool, " << spooled << " of "
            << all.size() << " cut\n";
  ASSERT_LT(spooled, all.size()) << "the car was meant to be killed mid-run";

  server = std::make_unique<ServerProcess>(store, server_log);
  Child again(car_command(spool, "", {}, 0.0), scratch.path() / "car-2.log");
  ASSERT_EQ(again.wait(60s), 0) << read_text(scratch.path() / "car-2.log");
  EXPECT_NE(read_text(scratch.path() / "car-2.log").find("resuming: " + std::to_string(pending)), std::string::npos)
      << read_text(scratch.path() / "car-2.log");
  dynid_cli(scratch.path(), {"close", "--vehicle", kVehicle, "--run", "car-killed"});
  ASSERT_EQ(server->stop(), 0) << read_text(server_log);

  const std::vector<ingest::Chunk> delivered(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(spooled));
  StoreReader stored(store);
  expect_stored_once(stored, "car-killed", delivered);
  const double worst = expect_same_estimates(stored.final_estimates("car-killed"),
                                             offline_estimates("car-killed", delivered), 1e-9);
  std::cout << "final estimates: largest relative difference to the uninterrupted processing " << worst << "\n";
}

}  // namespace
}  // namespace dynid::faults
