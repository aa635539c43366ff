// The spool's additions for dynid-car: run announcements kept for a restart, one chunk loaded
// by key. (The spool's chunk contract itself is tested in tests/car.)
#include <gtest/gtest.h>

#include <dynid/error.hpp>

#include "client_fixture.hpp"
#include "dynid/car/spool.hpp"

namespace dynid::car {
namespace {

using namespace testing;

TEST(ClientSpool, AnnouncementsSurviveARestartUntilTheRunIsAcknowledged) {
  ScratchDir dir("spool-ann");
  const auto a1 = make_announcement("car-1", "r1");
  const auto a2 = make_announcement("car-1", "r2");
  const auto c1 = make_chunks("car-1", "r1", 3);
  const auto c2 = make_chunks("car-1", "r2", 2);
  {
    Spool spool(dir.path(), 1 << 20);
    spool.store_announcement(a2);  // announced first, but its chunks come later
    spool.store_announcement(a1);
    spool.store_announcement(a1);  // again (a restart): no-op
    EXPECT_TRUE(spool.pending_announcements().empty()) << "no chunk yet: nothing to resend";
    spool.store(c1[0]);
    spool.store(c2[0]);
    spool.store(c1[1]);
    spool.store(c1[2]);
    spool.store(c2[1]);
  }
  Spool spool(dir.path(), 1 << 20);  // a restart
  auto pending = spool.pending_announcements();
  ASSERT_EQ(pending.size(), 2U);
  EXPECT_EQ(pending[0].run, "r1");  // order of the oldest pending chunk
  EXPECT_EQ(pending[1].run, "r2");
  EXPECT_EQ(ingest::encode_announcement(pending[0]), ingest::encode_announcement(a1));

  spool.acknowledge("car-1", "r1", 1);  // partly: r1 still has #2 to resend
  EXPECT_EQ(spool.pending_announcements().size(), 2U);
  spool.acknowledge("car-1", "r1", 2);
  pending = spool.pending_announcements();
  ASSERT_EQ(pending.size(), 1U);
  EXPECT_EQ(pending[0].run, "r2");
  // The announcement row of r1 is gone, not merely hidden: announcing r1 anew is accepted and a
  // different layout for r2 (still pending) is refused.
  auto other = a2;
  other.sample_rate_hz = 50.0;
  EXPECT_THROW(spool.store_announcement(other), InputError);
  auto a1_other = a1;
  a1_other.sample_rate_hz = 50.0;
  EXPECT_NO_THROW(spool.store_announcement(a1_other));
}

TEST(ClientSpool, LoadReturnsOnePendingChunkBitForBit) {
  ScratchDir dir("spool-load");
  const auto chunks = make_chunks("car-1", "r1", 4);
  Spool spool(dir.path(), 1 << 20);
  for (const auto& c : chunks) spool.store(c);
  const auto two = spool.load("car-1", "r1", 2);
  ASSERT_TRUE(two.has_value());
  EXPECT_TRUE(same_chunk(*two, chunks[2]));
  EXPECT_FALSE(spool.load("car-1", "r1", 9).has_value());
  EXPECT_FALSE(spool.load("car-2", "r1", 2).has_value());
  spool.acknowledge("car-1", "r1", 2);
  EXPECT_FALSE(spool.load("car-1", "r1", 2).has_value()) << "acknowledged chunks are gone";
  EXPECT_TRUE(spool.load("car-1", "r1", 3).has_value());
}

}  // namespace
}  // namespace dynid::car
