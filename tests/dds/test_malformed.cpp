// Malformed samples: the conversions refuse them with a readable reason, never crash or read
// past a buffer; over DDS, a malformed chunk is rejected and the next good one still passes.
#include <gtest/gtest.h>

#include <cstring>

#include "dds_fixture.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/writer.hpp"

namespace dynid::dds {
namespace {

using namespace testing;

/// The message of the InputError that `action` throws ("" and a test failure if none).
template <typename Action>
std::string rejection(Action action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no InputError";
  return {};
}

#define EXPECT_MENTIONS(message, part) \
  EXPECT_NE((message).find(part), std::string::npos) << "message: " << (message)

TEST(DdsMalformed, ChunkWhoseDataDoesNotMatchRowsTimesChannels) {
  auto sample = to_wire(make_chunk("proto-17", "run-3", 4, 2));
  sample.data.channels = 4;  // 2 x 4 = 8, data holds 6
  const auto message = rejection([&] { from_wire(sample.data); });
  EXPECT_MENTIONS(message, "Chunk proto-17/run-3#4");
  EXPECT_MENTIONS(message, "data holds 6 values, rows x channels = 2 x 4 = 8");
}

TEST(DdsMalformed, ChunkWithAbsurdOrMissingDimensions) {
  auto sample = to_wire(make_chunk("proto-17", "run-3", 4, 2));
  sample.data.rows = 4000000000u;
  EXPECT_MENTIONS(rejection([&] { from_wire(sample.data); }), "over the limits");
  sample.data.rows = 0;
  EXPECT_MENTIONS(rejection([&] { from_wire(sample.data); }), "empty chunk");
  sample.data.rows = 2;
  sample.data.valid._length = 1;
  EXPECT_MENTIONS(rejection([&] { from_wire(sample.data); }), "1 valid flags for 2 rows");
  sample.data.valid._length = 2;
  double* data = sample.data.data._buffer;
  sample.data.data._buffer = nullptr;  // claims 6 values, holds none
  EXPECT_MENTIONS(rejection([&] { from_wire(sample.data); }), "no buffer");
  sample.data.data._buffer = data;
  EXPECT_NO_THROW(from_wire(sample.data));  // the sample itself was fine
}

TEST(DdsMalformed, UnterminatedStringsAndDuplicateConstants) {
  auto chunk = to_wire(make_chunk("proto-17", "run-3", 0, 2));
  std::memset(chunk.data.run, 'r', sizeof chunk.data.run);
  EXPECT_MENTIONS(rejection([&] { from_wire(chunk.data); }), "run: string not terminated");

  auto announcement = make_announcement("proto-17", "run-3");
  auto sample = to_wire(announcement);
  auto& constants = sample.data.models._buffer[0].constants;
  ASSERT_EQ(constants._length, 2u);
  std::strcpy(constants._buffer[1].name, constants._buffer[0].name);
  EXPECT_MENTIONS(rejection([&] { from_wire(sample.data); }), "duplicate constant");
}

TEST(DdsMalformed, UnknownEnumValues) {
  EstimateTable t;
  t.vehicle = "A";
  t.model = "toy";
  t.parameters = {{"m", "kg", 1, 0.1, 10, ls::ParameterStatus::kIdentified, ""}};
  auto sample = to_wire(t);
  sample.data.parameters._buffer[0].status = static_cast<dynid_wire_ParameterStatus>(9);
  EXPECT_MENTIONS(rejection([&] { from_wire(sample.data); }), "unknown status 9");
  sample.data.parameters._buffer[0].status = dynid_wire_IDENTIFIED;
  sample.data.parameters._buffer[0].verdict = static_cast<dynid_wire_ParameterVerdict>(7);
  EXPECT_MENTIONS(rejection([&] { from_wire(sample.data); }), "unknown verdict 7");
  sample.data.parameters._buffer[0].status = dynid_wire_DEPENDENT;
  sample.data.parameters._buffer[0].verdict = dynid_wire_NOT_EXCITED;
  EXPECT_MENTIONS(rejection([&] { from_wire(sample.data); }), "not identified");
}

TEST(DdsMalformed, OversizeValuesAreRefusedBeforeTheyReachTheWire) {
  auto chunk = make_chunk("proto-17", "run-3", 0, 2);
  chunk.samples.resize(100001, 1);
  chunk.samples.setZero();
  chunk.valid.assign(100001, 1);
  EXPECT_MENTIONS(rejection([&] { to_wire(chunk); }), "at most 100000 rows");
  chunk.samples.resize(4200, 1000);  // each bound holds, the product does not
  chunk.samples.setZero();
  chunk.valid.assign(4200, 1);
  EXPECT_MENTIONS(rejection([&] { to_wire(chunk); }), "4200000 elements, at most 4194304");
  chunk = make_chunk(std::string(65, 'v'), "run-3", 0, 2);
  EXPECT_MENTIONS(rejection([&] { to_wire(chunk); }), "longer than 64 characters");
  chunk = make_chunk("proto-17", "run-3", 0, 2);
  chunk.valid.pop_back();
  EXPECT_MENTIONS(rejection([&] { to_wire(chunk); }), "1 valid flags for 2 rows");
}

TEST(DdsMalformed, OverDdsABadChunkIsRejectedAndTheNextGoodOnePasses) {
  Participant car(loopback_options());
  Participant server(loopback_options());
  Writer<dynid_wire_Chunk> writer(car, {vehicle_partition("proto-17")});
  Reader<dynid_wire_Chunk> reader(server, {vehicle_partition("proto-17")});
  ASSERT_TRUE(writer.wait_for_readers(1, kPatience));

  auto bad = to_wire(make_chunk("proto-17", "run-3", 0, 3));
  bad.data.rows = 5;  // a buggy or hostile car: 5 x 3 != 9 values
  ASSERT_TRUE(writer.write(bad.data));
  ASSERT_TRUE(writer.write(to_wire(make_chunk("proto-17", "run-3", 1, 3)).data));

  auto received = take_count(reader, 2);
  ASSERT_EQ(received.size(), 2u);
  int rejected = 0;
  std::vector<std::uint64_t> accepted;
  for (const auto& sample : received) {
    try {
      accepted.push_back(from_wire(sample.data).sequence);
    } catch (const InputError& error) {
      ++rejected;
      EXPECT_MENTIONS(std::string(error.what()), "rows x channels = 5 x 3 = 15");
    }
  }
  EXPECT_EQ(rejected, 1);
  EXPECT_EQ(accepted, std::vector<std::uint64_t>{1});
}

TEST(DdsMalformed, ASampleOverItsWireBoundIsNotSent) {
  Participant car(loopback_options());
  Participant server(loopback_options());
  Writer<dynid_wire_ChunkAck> writer(car, {vehicle_partition("proto-17")});
  Reader<dynid_wire_ChunkAck> reader(server, {vehicle_partition("proto-17")});
  ASSERT_TRUE(writer.wait_for_readers(1, kPatience));
  // Written raw, past to_wire(): 65 rejections in a sequence bounded at 64.
  auto sample = to_wire(ChunkReceipt{"proto-17", "run-3", 0, std::vector<ChunkRejection>(64)});
  std::vector<dynid_wire_Rejection> too_many(65);
  std::memset(too_many.data(), 0, sizeof(dynid_wire_Rejection) * too_many.size());
  dynid_wire_Rejection* kept = sample.data.rejections._buffer;
  sample.data.rejections._buffer = too_many.data();
  sample.data.rejections._length = sample.data.rejections._maximum = 65;
  bool sent = true;
  EXPECT_THROW(sent = writer.write(sample.data), DdsError);
  sample.data.rejections._buffer = kept;  // give Sample back what it owns
  sample.data.rejections._length = sample.data.rejections._maximum = 64;
  EXPECT_TRUE(sent);
  EXPECT_TRUE(reader.wait_take(300ms).empty());
}

}  // namespace
}  // namespace dynid::dds
