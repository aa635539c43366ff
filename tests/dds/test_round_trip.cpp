// Announcement, chunk and request/reply round trips between two participants on loopback:
// what the reader gets is bit for bit what the writer sent.
#include <gtest/gtest.h>

#include "dds_fixture.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/dds/writer.hpp"

namespace dynid::dds {
namespace {

using namespace testing;

TEST(DdsRoundTrip, AnnouncementArrivesUnchanged) {
  Participant car(loopback_options());
  Participant server(loopback_options());
  const auto sent = make_announcement("proto-17", "run-3");
  Writer<dynid_wire_RunAnnouncement> writer(car, {vehicle_partition("proto-17")});
  Reader<dynid_wire_RunAnnouncement> reader(server, {kAllVehiclesPartition});
  ASSERT_TRUE(writer.wait_for_readers(1, kPatience));
  ASSERT_TRUE(writer.write(to_wire(sent).data));

  auto received = take_count(reader, 1);
  ASSERT_EQ(received.size(), 1u);
  const auto got = from_wire(received[0].data);
  EXPECT_EQ(got.vehicle, sent.vehicle);
  EXPECT_EQ(got.run, sent.run);
  EXPECT_EQ(got.sample_rate_hz, sent.sample_rate_hz);
  ASSERT_EQ(got.channels.size(), sent.channels.size());
  for (std::size_t c = 0; c < sent.channels.size(); ++c) {
    EXPECT_EQ(got.channels[c].name, sent.channels[c].name);
    EXPECT_EQ(got.channels[c].unit, sent.channels[c].unit);
  }
  ASSERT_EQ(got.models.size(), sent.models.size());
  for (std::size_t m = 0; m < sent.models.size(); ++m) {
    EXPECT_EQ(got.models[m].model, sent.models[m].model);
    EXPECT_EQ(got.models[m].constants, sent.models[m].constants);
    EXPECT_EQ(got.models[m].effects, sent.models[m].effects);
  }
}

// Issue 16 item 5: the vehicle's preprocessing crosses the wire; an announcement whose
// preprocessing member is all zeros (an older car's, which lacks the member) reads as the
// server's defaults.
TEST(DdsRoundTrip, PreprocessingCrossesTheWireAndZerosMeanDefaults) {
  auto sent = make_announcement("proto-17", "run-4");
  sent.preprocessing.butterworth_order = 3;
  sent.preprocessing.cutoff_hz = 4.5;
  sent.preprocessing.odmf = 4;
  sent.preprocessing.channel_noise = {{sent.channels[0].name, 0.25}};
  const auto got = from_wire(to_wire(sent).data);
  EXPECT_EQ(got.preprocessing.butterworth_order, 3);
  EXPECT_EQ(got.preprocessing.cutoff_hz, 4.5);
  EXPECT_EQ(got.preprocessing.odmf, 4);
  EXPECT_EQ(got.preprocessing.channel_noise, sent.preprocessing.channel_noise);

  auto older = to_wire(make_announcement("proto-17", "run-5"));
  older.data.butterworth_order = 0;
  older.data.cutoff_hz = 0.0;
  older.data.odmf = 0;
  const auto defaults = from_wire(older.data);
  const ingest::Preprocessing expected;
  EXPECT_EQ(defaults.preprocessing.butterworth_order, expected.butterworth_order);
  EXPECT_EQ(defaults.preprocessing.odmf, expected.odmf);
  EXPECT_EQ(defaults.preprocessing.cutoff_hz, 0.0);
  EXPECT_NO_THROW(defaults.validate());
}

TEST(DdsRoundTrip, ChunksArriveBitForBitInOrder) {
  Participant car(loopback_options());
  Participant server(loopback_options());
  Writer<dynid_wire_Chunk> writer(car, {vehicle_partition("proto-17")});
  Reader<dynid_wire_Chunk> reader(server, {vehicle_partition("proto-17")});
  ASSERT_TRUE(writer.wait_for_readers(1, kPatience));
  std::vector<ingest::Chunk> sent;
  for (std::uint64_t s = 0; s < 4; ++s) {
    // 2000 rows x 3 doubles = 48 kB: fragmented on the wire.
    sent.push_back(make_chunk("proto-17", "run-3", s, 2000, static_cast<Eigen::Index>(s * 7)));
    ASSERT_TRUE(writer.write(to_wire(sent.back()).data));
  }
  auto received = take_count(reader, sent.size());
  ASSERT_EQ(received.size(), sent.size());
  for (std::size_t k = 0; k < sent.size(); ++k) {
    const auto got = from_wire(received[k].data);
    EXPECT_EQ(got.sequence, sent[k].sequence);
    EXPECT_EQ(got.first_sample_index, sent[k].first_sample_index);
    EXPECT_EQ(got.checksum, sent[k].checksum);
    EXPECT_EQ(got.valid, sent[k].valid);
    EXPECT_TRUE(same_bits(got.samples, sent[k].samples)) << "chunk " << k;
  }
}

TEST(DdsRoundTrip, RequestAndReplyKeepTheirCorrelation) {
  Participant engineer(loopback_options());
  Participant server(loopback_options());
  Writer<dynid_wire_Request> requests(engineer, {});
  Reader<dynid_wire_Request> incoming(server, {});
  Writer<dynid_wire_Reply> replies(server, {});
  Reader<dynid_wire_Reply> answers(engineer, {});
  ASSERT_TRUE(requests.wait_for_readers(1, kPatience));
  ASSERT_TRUE(replies.wait_for_readers(1, kPatience));

  const Request request{"alice@bench/42", 7, "estimate", {{"vehicle", "proto-17"}, {"model", "lateral_bicycle"}}};
  ASSERT_TRUE(requests.write(to_wire(request).data));
  auto got = take_count(incoming, 1);
  ASSERT_EQ(got.size(), 1u);
  const auto seen = from_wire(got[0].data);
  EXPECT_EQ(seen.client, request.client);
  EXPECT_EQ(seen.correlation_id, 7u);
  EXPECT_EQ(seen.kind, "estimate");
  ASSERT_EQ(seen.arguments.size(), 2u);
  EXPECT_EQ(seen.arguments[1].value, "lateral_bicycle");

  const std::string binary("a\0b\xff", 4);
  const Reply reply{seen.client, seen.correlation_id, ReplyStatus::kNotFound, "no estimate yet",
                    "application/octet-stream", binary, 2, 3};
  ASSERT_TRUE(replies.write(to_wire(reply).data));
  auto back = take_count(answers, 1);
  ASSERT_EQ(back.size(), 1u);
  const auto answer = from_wire(back[0].data);
  EXPECT_EQ(answer.correlation_id, 7u);
  EXPECT_EQ(answer.status, ReplyStatus::kNotFound);
  EXPECT_EQ(answer.error, "no estimate yet");
  EXPECT_EQ(answer.payload, binary);
  EXPECT_EQ(answer.shard, 2u);
  EXPECT_EQ(answer.shard_count, 3u);
}

}  // namespace
}  // namespace dynid::dds
