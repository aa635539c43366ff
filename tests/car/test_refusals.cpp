// Refusals that must never stall a run (label faults): a chunk the server refuses for good is
// set aside and the rest of the run delivered; a rejection the server's rule does not confirm is
// resent; a run whose name holds another recording stops with the server's reason. Over real
// Cyclone DDS against the test-side acknowledger (delivery_fixture.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>

#include "delivery_fixture.hpp"

namespace dynid::car {
namespace {

using namespace testing;

// A chunk the server refuses for good (a value past the limit: the car's own check with the
// server's rule confirms no resend can pass) never holds up the run: it is set aside in the spool
// with the reason, its rows go as invalid in its place, and the chunks after it are delivered.
// It once held them for good, resent at every attempt until the drain timeout.
TEST(ClientDelivery, AChunkRefusedForGoodIsSetAsideAndTheRestOfTheRunIsDelivered) {
  Link link("refused", {std::chrono::milliseconds(300), 32}, true);
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  car.delivery.announce(make_announcement("car-1", "r1"));
  auto chunks = make_chunks("car-1", "r1", 4);
  chunks[2].samples(1, 0) = 2.5e19;  // what an unchecked double signal once put into a chunk
  chunks[2].seal();
  for (const auto& c : chunks) car.delivery.submit(c);
  ASSERT_TRUE(link.until([&] { return link.acker.distinct("r1") == 4; }));
  const std::string reason = "chunk car-1/r1#2 invalid: row 1 (sample " +
                             std::to_string(chunks[2].first_sample_index + 1) +
                             "), channel 'a' = 25000000000000000000.000000 exceeds the limit";
  link.acker.acknowledge("r1", 1, {{2, reason}});
  // The stand-in: #2 again, its rows all invalid, its values ones a chunk may carry.
  const auto stand_in_arrived = [&] {
    return std::any_of(
        link.acker.received.begin(), link.acker.received.end(), [](const ingest::Chunk& c) {
          return c.sequence == 2 &&
                 std::all_of(c.valid.begin(), c.valid.end(), [](std::uint8_t v) { return v == 0; });
        });
  };
  ASSERT_TRUE(link.until(stand_in_arrived)) << car.delivery.holdup();
  for (const auto& c : link.acker.received)
    if (c.sequence == 2 &&
        std::all_of(c.valid.begin(), c.valid.end(), [](std::uint8_t v) { return v == 0; })) {
      EXPECT_EQ(c.first_sample_index, chunks[2].first_sample_index);
      EXPECT_EQ(c.samples.rows(), chunks[2].samples.rows());
      EXPECT_EQ(c.samples.cwiseAbs().maxCoeff(), 0.0);
      EXPECT_EQ(c.checksum, c.compute_checksum());
    }
  link.acker.acknowledge("r1", 3,
                         {{2, reason}});  // the stand-in stored: the old rejection is history
  ASSERT_TRUE(link.until([&] { return car.delivery.drained(); })) << car.delivery.holdup();
  EXPECT_EQ(car.spool.count(), 0U);
  EXPECT_EQ(car.delivery.stats().set_aside, 1U);
  EXPECT_EQ(car.delivery.stats().rejections, 1U);
  const auto refused = car.spool.refused();
  ASSERT_EQ(refused.size(), 1U);
  EXPECT_EQ(refused[0].sequence, 2U);
  EXPECT_EQ(refused[0].reason, reason);
  ASSERT_EQ(car.delivery.set_aside_report().size(), 1U);
  EXPECT_NE(car.delivery.set_aside_report()[0].find("car-1/r1#2 (samples "), std::string::npos);
  EXPECT_NE(car.delivery.set_aside_report()[0].find("refused for good by the server: " + reason),
            std::string::npos);
  EXPECT_TRUE(link.log.contains("rows sent as invalid in its place"));
}

// A rejection the server's rule does not confirm (the chunk is fine: it overtook its
// announcement) is resent as before, never set aside.
TEST(ClientDelivery, ARejectionOfAChunkTheRuleTakesIsResentNotSetAside) {
  Link link("not-refused", {std::chrono::milliseconds(300), 32}, true);
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  car.delivery.announce(make_announcement("car-1", "r1"));
  for (const auto& c : make_chunks("car-1", "r1", 3)) car.delivery.submit(c);
  ASSERT_TRUE(link.until([&] { return link.acker.distinct("r1") == 3; }));
  link.acker.acknowledge("r1", 0, {{1, "unknown run car-1/r1 (never announced)"}});
  ASSERT_TRUE(link.until([&] { return link.acker.copies("r1", 1) >= 2; }));
  EXPECT_EQ(car.delivery.stats().set_aside, 0U);
  EXPECT_TRUE(car.spool.refused().empty());
  link.acker.acknowledge("r1", 2);
  EXPECT_TRUE(link.until([&] { return car.delivery.drained(); }));
}

// A car whose run name the server holds with another recording's chunks stops with the server's
// reason. It once took the server's mark (the other recording's #6) as its own acknowledgement,
// deleted its unsent chunks and stopped at its next chunk with "spool: chunk clash#1 is already
// acknowledged (up to #6)".
TEST(ClientDelivery, ARunWhoseNameHoldsOtherContentStopsWithTheServersReason) {
  Link link("clash", {std::chrono::milliseconds(300), 32}, true);
  ASSERT_TRUE(link.connected);
  auto& car = link.car;
  car.delivery.announce(make_announcement("car-1", "clash"));
  // The announcement's receipt: the server holds #0..#6 of this name (another recording's).
  link.acker.acknowledge("clash", 6);
  car.delivery.service(200ms);
  const auto chunks = make_chunks("car-1", "clash", 3);
  car.delivery.submit(chunks[0]);
  EXPECT_EQ(car.spool.acknowledged("car-1", "clash"), std::nullopt)
      << "the other recording's mark is not ours";
  EXPECT_EQ(car.spool.count(), 1U);
  ASSERT_TRUE(link.until([&] { return link.acker.distinct("clash") == 1; }));
  car.delivery.submit(chunks[1]);  // once refused with "already acknowledged (up to #6)"
  const std::string reason = "chunk car-1/clash#0 is already stored with other content";
  link.acker.acknowledge("clash", 6, {{0, reason}});
  std::string refused;
  try {
    link.until([] { return false; }, 2s);
  } catch (const RunRefused& e) {
    refused = e.what();
  }
  EXPECT_NE(refused.find("the server refused run car-1/clash: " + reason), std::string::npos)
      << refused;
  EXPECT_NE(refused.find("replay this one under another --run"), std::string::npos) << refused;
  EXPECT_EQ(car.spool.count(), 0U) << "nothing of the run is resent at the next start";
  EXPECT_EQ(car.spool.refused().size(), 2U) << "and nothing is lost";
  EXPECT_EQ(car.spool.acknowledged("car-1", "clash"), std::nullopt);
  EXPECT_TRUE(car.delivery.drained());
}

}  // namespace
}  // namespace dynid::car
