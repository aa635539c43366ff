// The car's spool on a full filesystem (label faults), in-process: Spool and Delivery over
// real Cyclone DDS (loopback) against the client tests' acknowledger, the spool on a small
// tmpfs (SmallDisk). A refused write is SpoolWriteError naming the file and "disk full" and
// changes nothing; Delivery holds what it cannot spool, in order, sends nothing before it is
// spooled, and delivers everything once there is room.
#include <gtest/gtest.h>

#include "dynid/car/delivery.hpp"
#include "faults_fixture.hpp"

namespace dynid::faults {
namespace {

TEST(FaultsSpoolDiskFull, RefusedWriteNamesTheFileChangesNothingAndWorksAgainWithRoom) {
  ScratchDir scratch("faults-spool-full");
  SmallDisk disk(scratch.path(), 4ULL << 20);
  car::Spool spool(disk.path() / "spool", 1ULL << 30);
  const auto chunks = make_chunks("car-1", "r1", 3, 2000);
  spool.store(chunks[0]);
  disk.fill();
  try {
    spool.store(chunks[1]);
    FAIL() << "stored on a full disk";
  } catch (const car::SpoolWriteError& e) {
    EXPECT_NE(std::string(e.what()).find(spool.file().string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("disk full"), std::string::npos) << e.what();
  }
  EXPECT_EQ(spool.count(), 1U);
  EXPECT_EQ(spool.bytes(), ingest::encode_chunk(chunks[0]).size());
  disk.make_room();
  spool.store(chunks[1]);
  EXPECT_EQ(spool.count(), 2U);
}

TEST(FaultsSpoolDiskFull, DeliveryHoldsWhatItCannotSpoolInOrderAndDeliversItWithRoom) {
  ScratchDir scratch("faults-delivery-full");
  SmallDisk disk(scratch.path(), 4ULL << 20);
  dds::Participant server(loopback_options());
  TestAcker acker(server, "car-1");
  dds::Participant participant(loopback_options());
  car::Spool spool(disk.path() / "spool", 1ULL << 30);
  car::Uplink uplink(participant, "car-1");
  std::vector<std::string> errors;
  car::Delivery delivery(spool, uplink, {}, [&](car::LogLevel level, const std::string& message) {
    if (level == car::LogLevel::error) errors.push_back(message);
  });
  const auto serve = [&](auto done) {
    return acker.poll_until([&] {
      delivery.service(10ms);
      return done();
    });
  };
  ASSERT_TRUE(serve([&] { return uplink.readers_matched_total() > 0; }));
  delivery.announce(make_announcement("car-1", "r1"));
  const auto chunks = make_chunks("car-1", "r1", 8, 2000);
  for (std::size_t k = 0; k < 3; ++k) delivery.submit(chunks[k]);
  ASSERT_TRUE(serve([&] { return acker.contiguous("r1") == 2; }));

  disk.fill();
  for (std::size_t k = 3; k < chunks.size(); ++k) delivery.submit(chunks[k]);  // never throws
  acker.poll_until([] { return false; }, 500ms);
  EXPECT_EQ(acker.distinct("r1"), 3U) << "a chunk was sent before it was spooled";
  EXPECT_EQ(delivery.pending(), 5U);
  EXPECT_FALSE(delivery.drained());
  ASSERT_EQ(errors.size(), 1U) << "the outage is reported once";
  EXPECT_NE(errors[0].find("disk full"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find(spool.file().string()), std::string::npos) << errors[0];

  disk.make_room();
  ASSERT_TRUE(serve([&] { return delivery.drained(); })) << delivery.holdup();
  EXPECT_EQ(acker.contiguous("r1"), 7);
  for (std::size_t k = 0; k < chunks.size(); ++k) EXPECT_EQ(acker.copies("r1", k), 1U) << k;
  EXPECT_EQ(spool.count(), 0U);
}

}  // namespace
}  // namespace dynid::faults
