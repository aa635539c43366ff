// Scale-out's pieces without DDS (labels shard): the ownership function every server and
// client must agree on (FNV-1a 64 against the published test vectors, pinned owners), --shard
// parsing, the Reply's shard fields at the wire edge, and how the CLI merges the shards'
// replies (ShardReplies).
#include <gtest/gtest.h>

#include <set>

#include "dynid/cli/shard_replies.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/error.hpp"
#include "dynid/server/shard.hpp"

namespace dynid {
namespace {

using cli::ShardReplies;
using server::Shard;

TEST(ShardOwnership, Fnv1a64MatchesThePublishedVectors) {
  // Test vectors of the FNV reference (Fowler, Noll, Vo), 64-bit FNV-1a.
  EXPECT_EQ(server::fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(server::fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(server::fnv1a64("foobar"), 0x85944171f73967e8ULL);
}

TEST(ShardOwnership, OwnersArePinnedAndUnique) {
  // Computed independently (Python, the FNV-1a definition): a change of the function would move
  // vehicles away from the stores that hold them.
  const std::vector<std::pair<std::string, std::pair<unsigned, unsigned>>> pinned{
      {"shard-car-0", {1, 1}}, {"shard-car-1", {0, 0}}, {"shard-car-2", {1, 2}},
      {"shard-car-3", {0, 1}}, {"dynid-testcar", {0, 2}}};
  for (const auto& [vehicle, owners] : pinned) {
    EXPECT_EQ(Shard::owner_of(vehicle, 2), owners.first) << vehicle;
    EXPECT_EQ(Shard::owner_of(vehicle, 3), owners.second) << vehicle;
  }
  for (std::uint32_t n = 1; n <= 5; ++n) {
    for (int v = 0; v < 200; ++v) {
      const std::string vehicle = "car-" + std::to_string(v);
      int owners = 0;
      for (std::uint32_t k = 0; k < n; ++k) owners += Shard{k, n}.owns(vehicle) ? 1 : 0;
      EXPECT_EQ(owners, 1) << vehicle << " among " << n << " shards";
    }
  }
  const Shard one;
  EXPECT_TRUE(one.owns("anything"));
  EXPECT_EQ(Shard({1, 2}).foreign_vehicles({"shard-car-0", "shard-car-1", "shard-car-2"}),
            (std::vector<std::string>{"shard-car-1"}));
}

TEST(ShardOwnership, ParseAcceptsKOfNAndRefusesTheRest) {
  const Shard s = Shard::parse("2/3");
  EXPECT_EQ(s.index, 2u);
  EXPECT_EQ(s.count, 3u);
  EXPECT_EQ(s.to_string(), "2/3");
  for (const std::string bad : {"", "1", "2/2", "3/2", "a/2", "1/0", "-1/2", "0/2x", " 0/2", "0//2", "/2", "0/"}) {
    try {
      Shard::parse(bad);
      ADD_FAILURE() << "'" << bad << "' accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--shard '" + bad + "'"), std::string::npos) << e.what();
    }
  }
}

TEST(ShardReplyWire, ShardFieldsCrossTheEdgeAndBadOnesAreRefused) {
  dds::Reply reply{"alice@host/1", 7, dds::ReplyStatus::kOk, {}, "application/json", "[]", 1, 2};
  const auto back = dds::from_wire(dds::to_wire(reply).data);
  EXPECT_EQ(back.shard, 1u);
  EXPECT_EQ(back.shard_count, 2u);
  reply.shard = 2;
  EXPECT_THROW(dds::to_wire(reply), InputError);
  reply.shard = 0;
  auto sample = dds::to_wire(reply);
  sample.data.shard = 5;
  try {
    dds::from_wire(sample.data);
    ADD_FAILURE() << "shard 5 of 2 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shard 5 of 2"), std::string::npos) << e.what();
  }
}

dds::Reply reply(std::uint32_t shard, std::uint32_t count, std::string payload,
                 dds::ReplyStatus status = dds::ReplyStatus::kOk, std::string error = {}) {
  return {"c", 1, status, std::move(error), "application/json", std::move(payload), shard, count};
}

TEST(ShardMerge, CollectsOneReplyPerShardAndNamesTheMissing) {
  ShardReplies r;
  EXPECT_FALSE(r.complete());
  EXPECT_TRUE(r.missing().empty());
  EXPECT_TRUE(r.add(reply(2, 3, "[\"c\"]")));
  EXPECT_EQ(r.count(), 3u);
  EXPECT_FALSE(r.add(reply(2, 3, "[\"c\"]")));  // a resent answer
  EXPECT_TRUE(r.add(reply(0, 3, "[\"b\",\"a\"]")));
  EXPECT_FALSE(r.complete());
  EXPECT_EQ(r.missing(), std::vector<std::uint32_t>{1});
  EXPECT_EQ(cli::missing_note(r, 2000, "vehicles"),
            "shard 1/3 did not answer within 2000 ms: its vehicles are not included");
  EXPECT_EQ(cli::merged_vehicles(r), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_FALSE(r.failure());
  EXPECT_TRUE(r.add(reply(1, 3, "[\"a\",\"d\"]")));
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(cli::missing_note(r, 2000, "vehicles"), "");
  EXPECT_EQ(cli::merged_vehicles(r), (std::vector<std::string>{"a", "b", "c", "d"}));
}

TEST(ShardMerge, ServersDisagreeingOnTheShardCountAreNamed) {
  ShardReplies r;
  r.add(reply(0, 2, "[]"));
  try {
    r.add(reply(0, 3, "[]"));
    ADD_FAILURE() << "0/3 after 0/2 accepted";
  } catch (const cli::ShardMismatch& e) {
    EXPECT_NE(std::string(e.what()).find("shard 0/3 answered after shard 0/2"), std::string::npos) << e.what();
  }
}

TEST(ShardMerge, AServerThatDoesNotSayIsTheOnlyOne) {
  ShardReplies r;
  r.add(reply(0, 0, "{\"requests\":3}"));
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(r.count(), 1u);
  EXPECT_EQ(cli::merged_status(r), "{\"requests\":3}");  // one server: its counters as they are
}

TEST(ShardMerge, StatusOfSeveralShardsIsKeyedByShard) {
  ShardReplies r;
  r.add(reply(1, 3, "{\"requests\":2,\"not_owned\":5}"));
  r.add(reply(0, 3, "{\"requests\":1}"));
  EXPECT_EQ(cli::merged_status(r),
            "{\"shards\":{\"0/3\":{\"requests\":1},\"1/3\":{\"requests\":2,\"not_owned\":5}},\"missing\":[\"2/3\"]}");
  EXPECT_EQ(cli::missing_note(r, 10, "counters"),
            "shard 2/3 did not answer within 10 ms: its counters are not included");
  ShardReplies one_of_four;
  one_of_four.add(reply(2, 4, "{}"));
  EXPECT_EQ(cli::missing_note(one_of_four, 10, "counters"),
            "shards 0/4, 1/4, 3/4 did not answer within 10 ms: their counters are not included");
}

TEST(ShardMerge, RefusalsAndBadPayloadsAreReported) {
  ShardReplies r;
  r.add(reply(1, 2, "", dds::ReplyStatus::kBadRequest, "format 'xml' is neither text nor json"));
  r.add(reply(0, 2, "[\"a\"]"));
  ASSERT_TRUE(r.failure());
  EXPECT_EQ(r.failure()->shard, 1u);
  ShardReplies bad;
  bad.add(reply(1, 2, "[\"a\",3]"));
  try {
    cli::merged_vehicles(bad);
    ADD_FAILURE() << "a number taken for a vehicle";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shard 1/2"), std::string::npos) << e.what();
  }
  ShardReplies torn;
  torn.add(reply(0, 2, "[\"a\""));
  EXPECT_THROW(cli::merged_vehicles(torn), InputError);
  EXPECT_THROW(cli::merged_status(torn), InputError);
}

TEST(ShardMerge, VehicleListRendersAsTheServerDid) {
  const std::vector<std::string> vehicles{"a", "b \"quoted\""};
  EXPECT_EQ(cli::render_vehicles(vehicles, false), "a\nb \"quoted\"\n");
  EXPECT_EQ(cli::render_vehicles(vehicles, true), "[\"a\",\"b \\\"quoted\\\"\"]");
  EXPECT_EQ(cli::render_vehicles({}, false), "");
  EXPECT_EQ(cli::render_vehicles({}, true), "[]");
}

}  // namespace
}  // namespace dynid
