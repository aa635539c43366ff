// The server's wildcard readers take a per-vehicle sample only from a writer in that vehicle's
// own partition (dds/sender_partition.hpp): DDS Security confines a car to vehicle/<its id>,
// and this binds the sample's vehicle key to it, so a car cannot pass its data off as another's
// from inside its own partition. Plain loopback DDS (no security): the check is the server's.
#include <gtest/gtest.h>

#include "dynid/dds/conversions.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/dds/writer.hpp"
#include "ingest_test_support.hpp"
#include "security_fixture.hpp"

namespace dynid::security_test {
namespace {

template <typename T>
std::vector<std::string> vehicles_taken(dds::Reader<T>& reader, std::size_t expected) {
  std::vector<std::string> vehicles;
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (vehicles.size() < expected && std::chrono::steady_clock::now() < deadline)
    for (const auto& sample : reader.wait_take(100ms)) vehicles.emplace_back(sample.data.vehicle);
  for (const auto& sample : reader.wait_take(300ms)) vehicles.emplace_back(sample.data.vehicle);  // none more
  return vehicles;
}

ingest::test::TestRun run_of(const std::string& vehicle) {
  auto run = ingest::test::make_run(600, 3u);
  run.announcement.vehicle = vehicle;
  run.announcement.run = "run-1";
  return run;
}

TEST(SenderPartition, AWildcardReaderRefusesSamplesKeyedForAnotherVehicle) {
  dds::Participant car(dds::ParticipantOptions{kDomain, plain_config()});
  dds::Participant server(dds::ParticipantOptions{kDomain, plain_config()});
  dds::Writer<dynid_wire_Chunk> chunks(car, {dds::vehicle_partition("A")});
  dds::Writer<dynid_wire_RunAnnouncement> announcements(car, {dds::vehicle_partition("A")});
  dds::Reader<dynid_wire_Chunk> all_chunks(server, {dds::kAllVehiclesPartition});
  dds::Reader<dynid_wire_RunAnnouncement> all_announcements(server, {dds::kAllVehiclesPartition});
  dds::Reader<dynid_wire_Chunk> chunks_of_a(server, {dds::vehicle_partition("A")});
  ASSERT_TRUE(chunks.wait_for_readers(2, 10s));
  ASSERT_TRUE(announcements.wait_for_readers(1, 10s));

  const auto own = run_of("A"), forged = run_of("B");  // both written in vehicle/A
  ASSERT_TRUE(announcements.write(dds::to_wire(forged.announcement).data));
  ASSERT_TRUE(announcements.write(dds::to_wire(own.announcement).data));
  ASSERT_TRUE(chunks.write(dds::to_wire(ingest::test::cut(forged, 0, 0, 100)).data));
  ASSERT_TRUE(chunks.write(dds::to_wire(ingest::test::cut(own, 0, 0, 100)).data));

  EXPECT_EQ(vehicles_taken(all_chunks, 1), std::vector<std::string>{"A"});
  EXPECT_EQ(all_chunks.refused_by_partition(), 1u);
  EXPECT_EQ(vehicles_taken(all_announcements, 1), std::vector<std::string>{"A"});
  EXPECT_EQ(all_announcements.refused_by_partition(), 1u);
  // A reader of one vehicle's partition is not a wildcard reader: it takes what that partition
  // carries (only the server reads through the wildcard; its grant covers every vehicle).
  EXPECT_EQ(vehicles_taken(chunks_of_a, 2).size(), 2u);
  EXPECT_EQ(chunks_of_a.refused_by_partition(), 0u);
}

}  // namespace
}  // namespace dynid::security_test
