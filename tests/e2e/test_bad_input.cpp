// (c) Malformed chunks and requests are rejected with reasons the sender can read, counted,
// and change no state; the server keeps serving another vehicle meanwhile.
#include <cmath>
#include <limits>

#include "dynid/dds/conversions.hpp"
#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

struct BadChunk {
  std::string what;      // the case
  std::string expected;  // a word the reason must contain
  std::function<void(TestCar&, const std::vector<ingest::Chunk>&)> send;
};

ingest::Chunk resealed(ingest::Chunk chunk, const std::function<void(ingest::Chunk&)>& change) {
  change(chunk);
  chunk.seal();
  return chunk;
}

std::vector<BadChunk> bad_chunks() {
  return {
      {"wrong dimensions", "5 channels, the run announced 6",
       [](TestCar& car, const auto& c) {
         car.send(resealed(c[1], [](auto& k) { k.samples.conservativeResize(Eigen::NoChange, 5); }));
       }},
      {"NaN", "is NaN",
       [](TestCar& car, const auto& c) {
         car.send(resealed(c[1], [](auto& k) { k.samples(3, 1) = std::nan(""); }));
       }},
      {"absurd value", "exceeds the limit",
       [](TestCar& car, const auto& c) {
         car.send(resealed(c[1], [](auto& k) { k.samples(2, 0) = 1e300; }));
       }},
      {"bad checksum", "checksum",
       [](TestCar& car, const auto& c) {
         auto k = c[1];
         k.checksum ^= 1u;
         car.send(k);
       }},
      {"rows x channels against data length", "rows",
       [](TestCar& car, const auto& c) {
         auto sample = dds::to_wire(c[1]);
         sample.data.rows = 4000000000u;  // an absurd size claimed over a small payload
         car.send_raw(sample.data);
       }},
      {"duplicate sequence with other content", "other content",
       [](TestCar& car, const auto& c) {
         car.send(resealed(c[0], [](auto& k) { k.samples(0, 0) += 1.0; }));
       }},
      {"out of order, far ahead", "past the contiguous prefix",
       [](TestCar& car, const auto& c) {
         car.send(resealed(c[1], [](auto& k) { k.sequence = 1000; }));
       }},
      {"unknown run", "unknown run",
       [](TestCar& car, const auto& c) {
         car.send(resealed(c[1], [](auto& k) { k.run = "never-announced"; }));
       }},
  };
}

std::string reasons(const dds::ChunkReceipt& receipt) {
  std::string all;
  for (const auto& r : receipt.rejections) all += "#" + std::to_string(r.sequence) + ": " + r.reason + "\n";
  return all;
}

TEST(E2eBadInput, MalformedChunksAreRejectedWithReasonsAndChangeNothing) {
  TempDir dir;
  auto options = server_options(dir.file("store.db"));
  options.store.reorder_window = 8;
  InProcessServer server(options);

  // Another vehicle streams a good run all along.
  const auto good = test_run("good-car", "run-g", 21u);
  const auto good_chunks = cut_run(good, 4u);
  std::thread good_car([&] {
    TestCar car("good-car");
    EXPECT_TRUE(car.stream(good.announcement, good_chunks));
  });

  const auto run = test_run("bad-car", "run-b", 22u);
  const auto chunks = cut_run(run, 5u);
  TestCar car("bad-car");
  car.announce(run.announcement);
  ASSERT_TRUE(car.deliver(chunks, 0, 1));

  std::size_t rejections = 0;
  for (const auto& bad : bad_chunks()) {
    const auto before = server.server().counters().chunks_rejected;
    bad.send(car, chunks);
    const std::string run_id = bad.what == "unknown run" ? "never-announced" : "run-b";
    const auto receipt = car.wait_receipt(run_id, [&](const dds::ChunkReceipt& r) {
      return r.rejections.size() > (run_id == "run-b" ? rejections : 0);
    });
    ASSERT_TRUE(receipt.has_value()) << bad.what << ": no acknowledgement";
    ASSERT_FALSE(receipt->rejections.empty()) << bad.what << ": not rejected";
    EXPECT_NE(receipt->rejections.back().reason.find(bad.expected), std::string::npos)
        << bad.what << ": the reason should say '" << bad.expected << "'\n" << reasons(*receipt);
    EXPECT_EQ(receipt->highest_contiguous, run_id == "run-b" ? 0 : -1) << bad.what;
    if (run_id == "run-b") {
      ++rejections;
      EXPECT_EQ(receipt->rejections.size(), rejections) << bad.what << ": one rejection per bad chunk";
    }
    // The counter is server-wide: the good car's chunks that race its own announcement are
    // rejected (and resent) too, so only a lower bound holds here.
    EXPECT_GE(server.server().counters().chunks_rejected, before + 1) << bad.what;
  }

  // An exact duplicate is re-acknowledged, counted, and not folded again.
  car.send(chunks[0]);
  // The state is what it was: the run goes on from #1 as if nothing had been sent.
  ASSERT_TRUE(car.deliver(chunks, 1));
  EstimateWatcher bad_watcher("bad-car");
  const auto expected = references(offline(run, chunks).estimates());
  ASSERT_TRUE(bad_watcher.wait_for(expected, "run-b"));
  for (const auto& reference : expected) expect_equal(reference, bad_watcher.latest("run-b").at(reference.model));
  EXPECT_GE(server.server().counters().chunks_duplicate, 1u);

  good_car.join();
  EstimateWatcher good_watcher("good-car");
  const auto good_expected = references(offline(good, good_chunks).estimates());
  ASSERT_TRUE(good_watcher.wait_for(good_expected, "run-g"));
  for (const auto& reference : good_expected) expect_equal(reference, good_watcher.latest("run-g").at(reference.model));
  EXPECT_EQ(server.server().counters().chunks_folded, chunks.size() + good_chunks.size())
      << "each chunk folded once: no rejected one, no duplicate";
}

TEST(E2eBadInput, MalformedRequestsAreRejectedWithReasons) {
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  const auto run = test_run("req-car", "run-r", 31u);
  const auto chunks = cut_run(run, 6u);
  TestCar car("req-car");
  ASSERT_TRUE(car.stream(run.announcement, chunks));

  struct Case {
    std::string kind;
    std::vector<dds::RequestArgument> arguments;
    dds::ReplyStatus status;
    std::string expected;
  };
  const std::vector<Case> cases{
      {"explode", {}, dds::ReplyStatus::kBadRequest, "unknown kind 'explode'"},
      {"estimate", {}, dds::ReplyStatus::kBadRequest, "needs argument 'vehicle'"},
      {"estimate", {{"vehicle", "req-car"}, {"colour", "red"}}, dds::ReplyStatus::kBadRequest, "no argument 'colour'"},
      {"estimate", {{"vehicle", "req-car"}, {"format", "xml"}}, dds::ReplyStatus::kBadRequest, "neither text nor json"},
      {"estimate", {{"vehicle", "nobody"}}, dds::ReplyStatus::kNotFound, "unknown vehicle"},
      {"estimate", {{"vehicle", "req-car"}, {"run", "run-x"}}, dds::ReplyStatus::kNotFound, "unknown run"},
      {"estimate", {{"vehicle", "req-car"}, {"model", "warp_drive"}}, dds::ReplyStatus::kNotFound, "no model warp_drive"},
      {"pooled", {{"vehicle", "req-car"}, {"run", "run-r"}, {"run", "run-r"}}, dds::ReplyStatus::kBadRequest, "named twice"},
      {"reprocess", {{"vehicle", "req-car"}, {"run", "run-r"}, {"model", "warp_drive"}}, dds::ReplyStatus::kBadRequest, "warp_drive"},
      {"close", {{"vehicle", "req-car"}, {"run", "run-r"}, {"run", "run-s"}}, dds::ReplyStatus::kBadRequest, "given twice"},
  };
  for (const auto& c : cases) {
    const auto before = server.server().counters().requests_rejected;
    const auto reply = request(c.kind, c.arguments);
    EXPECT_EQ(reply.status, c.status) << c.kind << ": " << reply.error;
    EXPECT_NE(reply.error.find(c.expected), std::string::npos) << reply.error;
    EXPECT_EQ(server.server().counters().requests_rejected, before + 1) << c.kind;
  }
  // Nothing changed: the run is still open and its estimate is served.
  const auto runs = request("runs", {{"vehicle", "req-car"}});
  EXPECT_NE(runs.payload.find("open"), std::string::npos) << runs.payload;
  const auto estimate = request("estimate", {{"vehicle", "req-car"}});
  ASSERT_EQ(estimate.status, dds::ReplyStatus::kOk) << estimate.error;
  EXPECT_NE(estimate.payload.find("mass"), std::string::npos) << estimate.payload;
  // The remaining kinds answer on good input.
  const auto base = request("base", {{"vehicle", "req-car"}, {"run", "run-r"}, {"model", "longitudinal_wheel"}});
  ASSERT_EQ(base.status, dds::ReplyStatus::kOk) << base.error;
  EXPECT_NE(base.payload.find("base parameters"), std::string::npos) << base.payload;
  const auto reprocess = request("reprocess", {{"vehicle", "req-car"}, {"run", "run-r"}, {"model", "kinematic_longitudinal"}});
  ASSERT_EQ(reprocess.status, dds::ReplyStatus::kOk) << reprocess.error;
  EXPECT_NE(reprocess.payload.find("reprocess:run-r"), std::string::npos) << reprocess.payload;
}

}  // namespace
}  // namespace dynid::e2e
