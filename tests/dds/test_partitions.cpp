// Partitions per vehicle: a reader on vehicle/A never sees vehicle/B's data.
#include <gtest/gtest.h>

#include "dds_fixture.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/writer.hpp"

namespace dynid::dds {
namespace {

using namespace testing;

TEST(DdsPartitions, ReaderOnOneVehicleSeesOnlyThatVehicle) {
  Participant cars(loopback_options());
  Participant server(loopback_options());
  Writer<dynid_wire_Chunk> car_a(cars, {vehicle_partition("A")});
  Writer<dynid_wire_Chunk> car_b(cars, {vehicle_partition("B")});
  Reader<dynid_wire_Chunk> reader_a(server, {vehicle_partition("A")});
  Reader<dynid_wire_Chunk> reader_b(server, {vehicle_partition("B")});
  ASSERT_TRUE(car_a.wait_for_readers(1, kPatience));
  ASSERT_TRUE(car_b.wait_for_readers(1, kPatience));
  // Each writer matches only the reader of its own partition.
  EXPECT_FALSE(car_a.wait_for_readers(2, 300ms));

  ASSERT_TRUE(car_b.write(to_wire(make_chunk("B", "run-1", 0, 10)).data));
  ASSERT_TRUE(car_a.write(to_wire(make_chunk("A", "run-1", 0, 10)).data));
  ASSERT_TRUE(car_b.write(to_wire(make_chunk("B", "run-1", 1, 10)).data));

  auto got_a = take_count(reader_a, 1);
  ASSERT_EQ(got_a.size(), 1u);
  EXPECT_EQ(from_wire(got_a[0].data).vehicle, "A");
  EXPECT_TRUE(reader_a.wait_take(300ms).empty()) << "vehicle/A reader saw another partition";

  auto got_b = take_count(reader_b, 2);  // the control: B's chunks did travel
  ASSERT_EQ(got_b.size(), 2u);
  for (const auto& sample : got_b) EXPECT_EQ(from_wire(sample.data).vehicle, "B");
}

TEST(DdsPartitions, WildcardReaderSeesEveryVehicle) {
  Participant cars(loopback_options());
  Participant server(loopback_options());
  Writer<dynid_wire_Chunk> car_a(cars, {vehicle_partition("A")});
  Writer<dynid_wire_Chunk> car_b(cars, {vehicle_partition("B")});
  Reader<dynid_wire_Chunk> all(server, {kAllVehiclesPartition});
  ASSERT_TRUE(car_a.wait_for_readers(1, kPatience));
  ASSERT_TRUE(car_b.wait_for_readers(1, kPatience));
  ASSERT_TRUE(car_a.write(to_wire(make_chunk("A", "run-1", 0, 10)).data));
  ASSERT_TRUE(car_b.write(to_wire(make_chunk("B", "run-1", 0, 10)).data));
  EXPECT_EQ(take_count(all, 2).size(), 2u);
}

TEST(DdsPartitions, VehicleIdsThatWouldWidenThePartitionAreRefused) {
  EXPECT_EQ(vehicle_partition("proto-17"), "vehicle/proto-17");
  for (const std::string& bad : std::vector<std::string>{"", "*", "proto-*", "proto-1?", "a\\b", std::string(65, 'x')}) {
    try {
      vehicle_partition(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("partition"), std::string::npos) << error.what();
    }
  }
}

}  // namespace
}  // namespace dynid::dds
