// The car's delivery protocol over real Cyclone DDS (loopback): Delivery + Uplink against the
// test-side acknowledger. Spool first, then send; acknowledgements prune the spool; a lost
// link or a restart resends what is unacknowledged, in order; nothing is lost or duplicated
// while the link is fine.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "delivery_fixture.hpp"

namespace dynid::car {
namespace {

using namespace testing;

TEST(ClientDelivery, DeliversEveryChunkOnceInOrderAndAcksPruneTheSpool) {
  Link link("deliver");
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  car.delivery.announce(make_announcement("car-1", "r1"));
  const auto chunks = make_chunks("car-1", "r1", 12);
  for (const auto& c : chunks) car.delivery.submit(c);
  EXPECT_EQ(car.spool.count() + car.delivery.stats().acknowledged, 12U) << "stored before sent";
  ASSERT_TRUE(link.until([&] { return car.delivery.drained(); })) << car.delivery.holdup();

  EXPECT_EQ(car.spool.count(), 0U);
  EXPECT_EQ(car.spool.bytes(), 0U);
  EXPECT_EQ(car.delivery.stats().acknowledged, 12U);
  EXPECT_EQ(car.delivery.stats().resent, 0U);
  ASSERT_EQ(link.acker.received.size(), 12U) << "no chunk lost, none duplicated";
  for (std::size_t i = 0; i < chunks.size(); ++i) EXPECT_TRUE(same_chunk(link.acker.received[i], chunks[i])) << i;
  ASSERT_FALSE(link.acker.announcements.empty());
  EXPECT_EQ(link.acker.announcements.front().run, "r1");
  EXPECT_TRUE(car.delivery.server_knows("car-1", "r1"));
}

TEST(ClientDelivery, AcksPruneExactlyUpToTheAcknowledgedSequence) {
  Link link("prune", {}, true);
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  for (const auto& c : make_chunks("car-1", "r1", 10)) car.delivery.submit(c);
  ASSERT_TRUE(link.until([&] { return link.acker.distinct("r1") == 10; }));
  link.acker.acknowledge("r1", 4);
  ASSERT_TRUE(link.until([&] { return car.spool.count() == 5; }));
  std::vector<std::uint64_t> left;
  for (const auto& e : car.spool.pending_entries()) left.push_back(e.sequence);
  EXPECT_EQ(left, (std::vector<std::uint64_t>{5, 6, 7, 8, 9}));
  EXPECT_EQ(car.spool.acknowledged("car-1", "r1"), 4U);
  link.acker.acknowledge("r1", 2);  // an older receipt: nothing changes
  car.delivery.service(200ms);
  EXPECT_EQ(car.spool.count(), 5U);
}

TEST(ClientDelivery, ResendsInOrderWhenAcknowledgementsStop) {
  // The acker receives but never acknowledges: a one-way link.
  Link link("resend", {std::chrono::milliseconds(300), 32}, true);
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  const auto chunks = make_chunks("car-1", "r1", 6);
  for (const auto& c : chunks) car.delivery.submit(c);
  ASSERT_TRUE(link.until([&] { return link.acker.received.size() >= 12; }))
      << "expected a resend round after 300 ms without acknowledgement";
  EXPECT_GE(car.delivery.stats().resend_rounds, 1U);
  EXPECT_TRUE(link.log.contains("no acknowledgement for 300 ms: resending 6 unacknowledged chunks from car-1/r1#0"));
  // The resend is the same chunks, in order, from the oldest.
  for (std::size_t i = 0; i < 12; ++i) EXPECT_TRUE(same_chunk(link.acker.received[i], chunks[i % 6])) << i;
  EXPECT_EQ(car.spool.count(), 6U) << "nothing leaves the spool without an acknowledgement";

  link.acker.muted = false;
  ASSERT_TRUE(link.until([&] { return car.delivery.drained(); })) << car.delivery.holdup();
  EXPECT_EQ(link.acker.contiguous("r1"), 5);
}

TEST(ClientDelivery, TheWindowBoundsChunksInFlight) {
  Link link("window", {std::chrono::milliseconds(60000), 4}, true);
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  for (const auto& c : make_chunks("car-1", "r1", 10)) car.delivery.submit(c);
  ASSERT_TRUE(link.until([&] { return link.acker.received.size() >= 4; }));
  link.until([] { return false; }, 300ms);  // give extra sends time to show up
  EXPECT_EQ(link.acker.received.size(), 4U);
  EXPECT_EQ(car.delivery.in_flight(), 4U);
  link.acker.acknowledge("r1", 1);
  ASSERT_TRUE(link.until([&] { return link.acker.received.size() >= 6; }));
  link.until([] { return false; }, 300ms);
  EXPECT_EQ(link.acker.received.size(), 6U);
  EXPECT_EQ(link.acker.received.back().sequence, 5U);
}

TEST(ClientDelivery, ARestartAnnouncesAndResendsPendingRunsInOrder) {
  ScratchDir dir("restart");
  const auto r1 = make_chunks("car-1", "r1", 4);
  const auto r2 = make_chunks("car-1", "r2", 3);
  Log log;
  {  // first life: no server; the car spools and sends into the void, then stops
    Car car(dir.path(), {}, log);
    car.delivery.announce(make_announcement("car-1", "r1"));
    for (const auto& c : r1) car.delivery.submit(c);
    car.delivery.announce(make_announcement("car-1", "r2"));
    for (const auto& c : r2) car.delivery.submit(c);
    EXPECT_FALSE(car.delivery.drain(200ms));
    EXPECT_TRUE(car.delivery.holdup().find("no server ever matched") != std::string::npos) << car.delivery.holdup();
  }
  dds::Participant server(loopback_options());
  TestAcker acker(server, "car-1");
  Car car(dir.path(), {std::chrono::milliseconds(60000), 32}, log);  // second life
  EXPECT_TRUE(log.contains("resuming: 7 unacknowledged chunks in the spool (2 runs announced again)"));
  ASSERT_TRUE(run_until(car, acker, [&] { return car.delivery.drained(); })) << car.delivery.holdup();
  // Well before the 60 s ack timeout: the car resent on the server's appearance.
  ASSERT_EQ(acker.received.size(), 7U) << "each chunk exactly once";
  for (std::size_t i = 0; i < 4; ++i) EXPECT_TRUE(same_chunk(acker.received[i], r1[i])) << i;
  for (std::size_t i = 0; i < 3; ++i) EXPECT_TRUE(same_chunk(acker.received[4 + i], r2[i])) << i;
  std::vector<std::string> runs;
  for (const auto& a : acker.announcements) runs.push_back(a.run);
  EXPECT_NE(std::find(runs.begin(), runs.end(), "r1"), runs.end());
  EXPECT_NE(std::find(runs.begin(), runs.end(), "r2"), runs.end());
  EXPECT_EQ(car.spool.count(), 0U);
  EXPECT_TRUE(car.spool.pending_announcements().empty());
}

TEST(ClientDelivery, RejectionsAreReportedWithTheirReasonAndHoldTheRun) {
  Link link("reject", {}, true);
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  for (const auto& c : make_chunks("car-1", "r1", 4)) car.delivery.submit(c);
  ASSERT_TRUE(link.until([&] { return link.acker.distinct("r1") == 4; }));
  const std::size_t before = link.acker.received.size();
  link.acker.acknowledge("r1", 1, {{2, "row 3, channel vx: value is NaN"}});
  ASSERT_TRUE(link.until([&] { return car.spool.count() == 2; }));
  EXPECT_FALSE(car.delivery.drain(300ms));
  EXPECT_TRUE(link.log.contains("server rejected car-1/r1#2: row 3, channel vx: value is NaN"));
  EXPECT_EQ(car.delivery.stats().rejections, 1U);
  EXPECT_TRUE(car.delivery.holdup().find("the server rejected it: row 3, channel vx: value is NaN") !=
              std::string::npos)
      << car.delivery.holdup();
  // A new rejection of a pending chunk is resent at once (it may have overtaken its run's
  // announcement), the same rejection again is not.
  ASSERT_TRUE(link.until([&] { return link.acker.received.size() >= before + 2; }));
  EXPECT_EQ(car.delivery.stats().resend_rounds, 1U);
  link.acker.acknowledge("r1", 1, {{2, "row 3, channel vx: value is NaN"}});
  car.delivery.service(200ms);
  EXPECT_EQ(car.delivery.stats().rejections, 1U) << "a rejection is reported once";
  EXPECT_EQ(car.delivery.stats().resend_rounds, 1U);
  EXPECT_EQ(car.spool.count(), 2U) << "a rejected chunk is kept, never dropped silently";
  // The announcement's own rejection is named as such.
  link.acker.acknowledge("r1", 1, {{~std::uint64_t{0}, "announcement rejected: no channel"}});
  car.delivery.service(200ms);
  EXPECT_TRUE(link.log.contains("server rejected the announcement of car-1/r1: announcement rejected: no channel"));
}

// The vehicle's other cars share its partition and see each other's receipts: another run's
// rejection is not this car's, neither in its log nor in its count.
TEST(ClientDelivery, AnotherRunsRejectionIsNotThisCarsNews) {
  Link link("others", {}, true);
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  for (const auto& c : make_chunks("car-1", "r1", 3)) car.delivery.submit(c);
  ASSERT_TRUE(link.until([&] { return link.acker.distinct("r1") == 3; }));
  link.acker.acknowledge("bound", 18,
                         {{19, "row 99 (sample 1999), channel 'vx' = 2.5e19 exceeds the limit"}});
  link.acker.acknowledge("r1", 2, {});
  ASSERT_TRUE(link.until([&] { return car.spool.count() == 0; }));
  car.delivery.service(200ms);
  EXPECT_FALSE(link.log.contains("bound#19"));
  EXPECT_EQ(car.delivery.stats().rejections, 0U);
  EXPECT_TRUE(car.delivery.drain(300ms));
}

}  // namespace
}  // namespace dynid::car
