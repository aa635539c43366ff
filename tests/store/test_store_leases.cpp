// Leases on every backend (store_contract.hpp; store.hpp, Leases): two store clients, as two
// servers would hold them, contend for one vehicle; the second takes it over once the first's
// lease expires, and from then on the first can write nothing of that vehicle.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "dynid/error.hpp"
#include "store_contract.hpp"

namespace dynid::store::test {
namespace {

using namespace std::chrono_literals;

constexpr auto kTtl = 1000ms;  // long against a store write under the sanitizers and a loaded disk

StoreOptions held_by(const std::string& holder) {
  StoreOptions options;
  options.holder = holder;
  return options;
}

// Polls acquire_lease until it is holder's, for at most `within`; how long that took.
std::chrono::milliseconds time_to_take(Store& store, const std::string& holder,
                                       std::chrono::milliseconds within) {
  const auto start = std::chrono::steady_clock::now();
  while (store.acquire_lease("proto-17", holder, kTtl).holder != holder &&
         std::chrono::steady_clock::now() - start < within) {
    std::this_thread::sleep_for(20ms);
  }
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() -
                                                               start);
}

TEST_P(StoreLeases, TheSecondClientTakesTheVehicleOverOnceTheFirstsLeaseExpires) {
  Store first = open(held_by("server-a"));
  Store second = open(held_by("server-b"));
  EXPECT_EQ(first.acquire_lease("proto-17", "server-a", kTtl).holder, "server-a");
  first.add_run(announcement("proto-17", "run-1"));
  ASSERT_EQ(first.store_chunk(chunk("proto-17", "run-1", 0)).status, ChunkStatus::stored);

  // Contended: the second sees the first's lease and may write nothing of the vehicle.
  EXPECT_EQ(second.acquire_lease("proto-17", "server-b", kTtl).holder, "server-a");
  try {
    second.store_chunk(chunk("proto-17", "run-1", 1));
    FAIL() << "a client without the lease stored a chunk";
  } catch (const NotHolderError& e) {
    EXPECT_NE(std::string(e.what()).find("held by server-a"), std::string::npos) << e.what();
  }
  EXPECT_EQ(first.highest_contiguous({"proto-17", "run-1"}), 0u);

  // The first renews once, then stops (a server that died): the second takes over after
  // the renewed lease expires, not before.
  const auto renewed = first.acquire_lease("proto-17", "server-a", kTtl);
  EXPECT_EQ(renewed.holder, "server-a");
  const auto waited = time_to_take(second, "server-b", 5s);
  EXPECT_GE(waited, kTtl - 50ms);  // the renewal's ttl, less the time since it was taken
  EXPECT_LT(waited, 5s) << "the expired lease was never taken over";

  // The new holder continues the run where the first left it; the first is fenced out.
  EXPECT_EQ(second.store_chunk(chunk("proto-17", "run-1", 1)).contiguous_through, 1u);
  EXPECT_THROW(first.store_chunk(chunk("proto-17", "run-1", 2)), NotHolderError);
  EXPECT_THROW(first.mark_folded({"proto-17", "run-1"}, 0), NotHolderError);
  EXPECT_EQ(first.acquire_lease("proto-17", "server-a", kTtl).holder, "server-b");
  const auto leases = second.leases();
  ASSERT_EQ(leases.size(), 1u);
  EXPECT_EQ(leases[0].vehicle, "proto-17");
  EXPECT_EQ(leases[0].holder, "server-b");
}

TEST_P(StoreLeases, AReleasedLeaseIsTakenAtOnceAndOnlyItsHolderReleasesIt) {
  Store first = open(held_by("server-a"));
  Store second = open(held_by("server-b"));
  first.acquire_lease("proto-17", "server-a", 60s);
  second.release_lease("proto-17", "server-b");  // not its lease: nothing happens
  EXPECT_EQ(second.acquire_lease("proto-17", "server-b", 60s).holder, "server-a");
  first.release_lease("proto-17", "server-a");  // a server that stops hands over at once
  EXPECT_EQ(second.acquire_lease("proto-17", "server-b", 60s).holder, "server-b");
  second.add_run(announcement("proto-17", "run-1"));
  EXPECT_THROW(first.add_run(announcement("proto-17", "run-2")), NotHolderError);
  EXPECT_THROW(first.acquire_lease("proto-17", "", 60s), InputError);
  EXPECT_THROW(first.acquire_lease("proto-17", "server-a", 0ms), InputError);
}

// Folds live in their server's memory: a server that opens a shared store leaves the others'
// folded marks alone, and the one that takes a vehicle over sets that vehicle's marks back to
// its checkpoints (it folds again from there), and no other vehicle's.
TEST_P(StoreLeases, ATakeoverSetsOnlyItsVehiclesFoldedMarksBackToTheirCheckpoints) {
  Store first = open(held_by("server-a"));
  for (const char* vehicle : {"proto-17", "proto-18"}) {
    first.acquire_lease(vehicle, "server-a", 60s);
    first.add_run(announcement(vehicle, "run-1"));
    for (std::uint64_t s = 0; s < 6; ++s) first.store_chunk(chunk(vehicle, "run-1", s));
    first.save_checkpoint({vehicle, "run-1"}, 2, "checkpoint");
    first.mark_folded({vehicle, "run-1"}, 5);
  }
  Store second = open(held_by("server-b"));
  EXPECT_EQ(second.folded_through({"proto-17", "run-1"}), 5u);  // opening changed nothing
  StoreOptions keeper;  // a server's lease keeper: shared, not fenced
  keeper.shared = true;
  Store unfenced = open(keeper);
  EXPECT_EQ(unfenced.folded_through({"proto-17", "run-1"}), 5u);
  EXPECT_THROW(second.restart_folds("proto-17"), NotHolderError);  // not its vehicle yet

  first.release_lease("proto-17", "server-a");
  ASSERT_EQ(second.acquire_lease("proto-17", "server-b", 60s).holder, "server-b");
  second.restart_folds("proto-17");
  EXPECT_EQ(second.folded_through({"proto-17", "run-1"}), 2u);
  second.mark_folded({"proto-17", "run-1"}, 3);  // the new holder's replay moves it forward
  EXPECT_EQ(second.folded_through({"proto-18", "run-1"}), 5u);  // the other vehicle's stays
  second.acquire_lease("never-seen", "server-b", 60s);
  EXPECT_NO_THROW(second.restart_folds("never-seen"));  // no runs: nothing to do
}

}  // namespace
}  // namespace dynid::store::test
