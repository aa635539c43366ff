// (b) dynid-server as a process, killed with SIGKILL in the middle of a run and restarted on
// the same store: every acknowledged chunk is in the store, the ledger has folded each chunk
// exactly once, and the final estimate equals the uninterrupted run's to 1e-12.
#include <signal.h>
#include <sys/wait.h>

#include <fstream>
#include <iterator>

#include "dynid/store/store.hpp"
#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

std::vector<std::string> server_arguments(const TempDir& dir) {
  return {"--store", dir.file("store.db"), "--cyclone-config", loopback_config(), "--domain",
          std::to_string(kDomain), "--threads", "2", "--checkpoint-every", "3",
          "--publish-interval-ms", "20", "--log-level", "info"};
}

std::string log_of(const TempDir& dir) {
  std::ifstream in(dir.file("server.log"));
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(E2eRestart, SigkillMidRunLosesNothingAndFoldsNothingTwice) {
  TempDir dir;
  const auto run = test_run("restart-car", "run-k", 5u);
  const auto chunks = cut_run(run, 3u, 500);
  ASSERT_GE(chunks.size(), 16u);
  // Killed after a chunk that ends no checkpoint step (every 3): the restart must replay.
  std::size_t before_kill = chunks.size() / 2;
  if (before_kill % 3 == 0) ++before_kill;
  TestCar car("restart-car");
  EstimateWatcher watcher("restart-car");
  {
    ServerProcess first(server_arguments(dir), dir.file("server.log"));
    car.announce(run.announcement);
    ASSERT_TRUE(car.deliver(chunks, 0, before_kill)) << log_of(dir);
    first.signal(SIGKILL);
    const auto status = first.wait(10s);
    ASSERT_TRUE(status && WIFSIGNALED(*status)) << "the server did not die of SIGKILL";
  }
  ServerProcess second(server_arguments(dir), dir.file("server.log"));
  ASSERT_TRUE(car.deliver(chunks, before_kill)) << log_of(dir);

  const auto expected = references(offline(run, chunks).estimates());
  ASSERT_TRUE(watcher.wait_for(expected, "run-k"))
      << log_of(dir);
  for (const auto& reference : expected) expect_equal(reference, watcher.latest("run-k").at(reference.model));

  // The ledger, as the running server sees it: everything stored is folded, once.
  const auto runs = request("runs", {{"vehicle", "restart-car"}, {"format", "json"}});
  ASSERT_EQ(runs.status, dds::ReplyStatus::kOk) << runs.error;
  const std::string last = std::to_string(chunks.size() - 1);
  EXPECT_NE(runs.payload.find("\"contiguous_through\":" + last + ",\"folded_through\":" + last),
            std::string::npos)
      << runs.payload;
  const auto status = request("status", {});
  EXPECT_NE(status.payload.find("\"chunks_replayed\":"), std::string::npos);
  EXPECT_EQ(status.payload.find("\"chunks_replayed\":0,"), std::string::npos)
      << "the restarted server should have replayed the chunks after its checkpoint: " << status.payload;
  EXPECT_EQ(log_of(dir).find("folded twice"), std::string::npos) << log_of(dir);

  second.signal(SIGTERM);
  const auto exit_status = second.wait(10s);
  ASSERT_TRUE(exit_status && WIFEXITED(*exit_status) && WEXITSTATUS(*exit_status) == 0)
      << "SIGTERM must stop the server cleanly\n" << log_of(dir);

  // Every acknowledged chunk is in the store, bit for bit.
  store::Store store(dir.file("store.db"));
  const store::RunKey key{"restart-car", "run-k"};
  ASSERT_EQ(store.highest_contiguous(key), chunks.size() - 1);
  auto stream = store.chunks(key, 0, chunks.size() - 1);
  for (const auto& sent : chunks) {
    const auto stored = stream.next();
    ASSERT_TRUE(stored.has_value());
    EXPECT_EQ(ingest::encode_chunk(*stored), ingest::encode_chunk(sent));
  }
}

}  // namespace
}  // namespace dynid::e2e
