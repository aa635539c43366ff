// Twenty SIGKILLs of dynid-server while dynid-car streams a simulated run into it (labels
// faults, slow). Each kill is restarted on the same store. The kill points are random (seeded;
// the seed and every point are printed, DYNID_FAULT_SEED=<seed> replays them) and spread over
// the whole run: some right after an acknowledgement is observed (the server is then folding
// and checkpointing the chunk it just stored), some a random delay after one, some while the
// freshly started server resumes its runs. Afterwards, from the store read read-only: every
// chunk stored exactly once and bit for bit, the ledger folded through the last one; and the
// final estimates equal those of the same log delivered without interruption.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <random>
#include <thread>

#include "faults_fixture.hpp"

namespace dynid::faults {
namespace {

enum class KillKind { right_after_ack, delayed_after_ack, during_resume };

const char* name_of(KillKind kind) {
  switch (kind) {
    case KillKind::right_after_ack: return "right after the ack";
    case KillKind::delayed_after_ack: return "after the ack +";
    case KillKind::during_resume: return "while resuming, at start +";
  }
  return "?";
}

struct KillPoint {
  KillKind kind = KillKind::right_after_ack;
  std::int64_t after_ack = 0;   // the acknowledged sequence to wait for
  std::chrono::milliseconds delay{0};
};

unsigned fault_seed() {
  const char* text = std::getenv("DYNID_FAULT_SEED");
  return text ? static_cast<unsigned>(std::strtoul(text, nullptr, 10)) : 20261121u;
}

// `count` kill points over acknowledged sequences 1..chunks-2, ascending, so they spread over
// the run and each incarnation of the server makes progress before it dies.
std::vector<KillPoint> kill_plan(unsigned seed, int count, std::int64_t chunks) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<std::int64_t> sequence(1, chunks - 2);
  std::uniform_int_distribution<int> kind(0, 2), delay(0, 600);
  std::vector<std::int64_t> acks;
  for (int k = 0; k < count; ++k) acks.push_back(sequence(random));
  std::sort(acks.begin(), acks.end());
  std::vector<KillPoint> plan;
  for (const auto ack : acks) {
    const auto k = static_cast<KillKind>(kind(random));
    plan.push_back({k, ack, std::chrono::milliseconds(k == KillKind::right_after_ack ? 0 : delay(random))});
  }
  return plan;
}

TEST(FaultsServerKills, TwentyRandomKillsWhileStreamingLoseNothingAndFoldNothingTwice) {
  const unsigned seed = fault_seed();
  ScratchDir scratch("faults-kills");
  const auto log = simulated_run("sine_steer", scratch) / "can.log";
  const auto expected = expected_chunks(log, "killed");
  ASSERT_GE(expected.size(), 30U);
  const auto plan = kill_plan(seed, 20, static_cast<std::int64_t>(expected.size()));
  std::cout << "fault seed " << seed << " (DYNID_FAULT_SEED), " << expected.size() << " chunks\n";
  // OpenBLAS starts a thread at load, before dynid-server installs its SIGTERM handling; with
  // one BLAS thread the final SIGTERM stops the server cleanly (as deploy/demo.sh does).
  setenv("OPENBLAS_NUM_THREADS", "1", 1);
  const auto store = scratch.path() / "store.db";
  const auto server_log = scratch.path() / "server.log";
  const auto car_log = scratch.path() / "car.log";
  AckWatch acks;

  const auto started = std::chrono::steady_clock::now();
  const auto ms_since_start = [&] {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - started).count();
  };
  auto server = std::make_unique<ServerProcess>(store, server_log);
  // Twice real time: ~20 s of reading, so the car is cutting and spooling chunks while the
  // server keeps dying; what arrives while it is down waits in the spool.
  Child car(car_command(scratch.path() / "spool", "killed", log, 2.0), car_log);
  int while_reading = 0;
  for (std::size_t k = 0; k < plan.size(); ++k) {
    const KillPoint& point = plan[k];
    if (point.kind == KillKind::during_resume) {
      std::this_thread::sleep_for(point.delay);
    } else {
      ASSERT_TRUE(acks.wait("killed", point.after_ack, 30s))
          << "kill " << k << ": no acknowledgement through #" << point.after_ack << " (highest #" << acks.highest()
          << ")\n" << read_text(server_log) << read_text(car_log);
      std::this_thread::sleep_for(point.delay);
    }
    std::string why;
    ASSERT_TRUE(server->kill(why)) << "kill " << k << ": " << why << "\n" << read_text(server_log);
    const bool reading = read_text(car_log).find("replay done") == std::string::npos;
    while_reading += reading;
    std::cout << "kill " << k + 1 << " at " << ms_since_start() << " ms: " << name_of(point.kind)
              << (point.kind == KillKind::right_after_ack ? "" : std::to_string(point.delay.count()) + " ms")
              << (point.kind == KillKind::during_resume ? "" : " through #" + std::to_string(point.after_ack))
              << ", acknowledged through #" << acks.highest() << (reading ? ", car reading" : ", car draining")
              << "\n";
    acks.take("killed", 0ms);  // what the dead server sent last
    server = std::make_unique<ServerProcess>(store, server_log);
  }
  const auto car_status = car.wait(90s);
  ASSERT_EQ(car_status, 0) << read_text(car_log);
  std::cout << "20 kills in " << ms_since_start() << " ms, " << while_reading << " while the car was reading\n";

  // The same log without interruption, as another run of the vehicle on the same server.
  Child reference(car_command(scratch.path() / "spool-ref", "uninterrupted", log, 0.0),
                  scratch.path() / "car-ref.log");
  ASSERT_EQ(reference.wait(90s), 0) << read_text(scratch.path() / "car-ref.log");
  dynid_cli(scratch.path(), {"close", "--vehicle", kVehicle, "--run", "killed"});
  dynid_cli(scratch.path(), {"close", "--vehicle", kVehicle, "--run", "uninterrupted"});
  ASSERT_EQ(server->stop(), 0) << read_text(server_log);
  const std::string server_text = read_text(server_log);
  EXPECT_EQ(server_text.find("folded twice"), std::string::npos) << server_text;

  StoreReader stored(store);
  expect_stored_once(stored, "killed", expected);
  expect_stored_once(stored, "uninterrupted", expected_chunks(log, "uninterrupted"));
  const double worst = expect_same_estimates(stored.final_estimates("killed"),
                                             stored.final_estimates("uninterrupted"), 1e-9);
  std::cout << "final estimates: largest relative difference to the uninterrupted run " << worst << "\n";
}

}  // namespace
}  // namespace dynid::faults
