// (a) A run streamed chunk by chunk through dynid-server (in-process): the published estimate
// equals an offline RunProcessor of the same chunks to 1e-12 relative, standard deviations
// included, while the run streams and after it is closed.
#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

TEST(E2eStreaming, PublishedEstimateEqualsOfflineProcessor) {
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  const auto run = test_run("stream-car", "run-1", 7u);
  const auto chunks = cut_run(run, 11u);
  ASSERT_GE(chunks.size(), 10u);

  TestCar car("stream-car");
  EstimateWatcher watcher("stream-car");
  ASSERT_TRUE(car.stream(run.announcement, chunks));

  auto processor = offline(run, chunks);
  const auto streaming = references(processor.estimates());
  ASSERT_EQ(streaming.size(), 3u) << "every model of the test run has an estimate";
  ASSERT_TRUE(watcher.wait_for(streaming, "run-1"))
      << "no estimate with the offline row counts was published: " << [&] {
           std::string s = "seen " + watcher.seen() + " ";
           for (const auto& r : streaming) s += "expected " + r.model + " " + std::to_string(r.rows) + "; ";
           return s;
         }();
  for (const auto& expected : streaming) expect_equal(expected, watcher.latest("run-1").at(expected.model));

  // Closing folds the samples held back for the filter's look-ahead: compare with finish().
  const auto reply = request("close", {{"vehicle", "stream-car"}, {"run", "run-1"}});
  ASSERT_EQ(reply.status, dds::ReplyStatus::kOk) << reply.error;
  processor.finish();
  const auto closed = references(processor.estimates());
  ASSERT_TRUE(watcher.wait_for(closed, "run-1"));
  for (const auto& expected : closed) expect_equal(expected, watcher.latest("run-1").at(expected.model));
  EXPECT_NE(reply.payload.find("longitudinal_wheel"), std::string::npos) << reply.payload;

  const auto counters = server.server().counters();
  EXPECT_EQ(counters.chunks_stored, chunks.size());
  EXPECT_EQ(counters.chunks_folded, chunks.size());
  EXPECT_EQ(counters.chunks_rejected, 0u);
  EXPECT_GE(counters.checkpoints, chunks.size() / 4);
}

// Issue 16 item 5: the vehicle's preprocessing (here odmf 4 and a 6 Hz cut-off instead of the
// defaults 8 and DYCARO's rule) crosses the wire and is the one the server processes with: its
// estimates equal an offline processor of the same announcement, row counts included (odmf 4
// builds about twice the rows of the default).
TEST(E2eStreaming, TheServerProcessesWithTheAnnouncedPreprocessing) {
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  auto run = test_run("prep-car", "run-p", 9u);
  run.announcement.preprocessing.odmf = 4;
  run.announcement.preprocessing.cutoff_hz = 6.0;
  const auto chunks = cut_run(run, 13u);
  TestCar car("prep-car");
  EstimateWatcher watcher("prep-car");
  ASSERT_TRUE(car.stream(run.announcement, chunks));
  auto processor = offline(run, chunks);
  const auto expected = references(processor.estimates());
  ASSERT_TRUE(watcher.wait_for(expected, "run-p")) << "seen " << watcher.seen();
  for (const auto& e : expected) expect_equal(e, watcher.latest("run-p").at(e.model));

  auto defaults = run;
  defaults.announcement.preprocessing = {};
  const auto default_rows = references(offline(defaults, chunks).estimates());
  ASSERT_EQ(default_rows.size(), expected.size());
  EXPECT_GT(expected[0].rows, default_rows[0].rows * 3 / 2) << "odmf 4 against 8";
}

}  // namespace
}  // namespace dynid::e2e
