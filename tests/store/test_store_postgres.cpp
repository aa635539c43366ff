// The contract suite (store_contract.hpp) on a real PostgreSQL server that this test process
// starts itself (postgres_cluster.hpp), a new schema per test; and what only a shared
// database adds: two store clients writing the same run at once, a server crash, a database
// that is not ours or is newer, a server that would not make commits durable.
#include <gtest/gtest.h>

#include <optional>
#include <thread>

#include "dynid/error.hpp"
#include "postgres_cluster.hpp"
#include "store_contract.hpp"

namespace dynid::store::test {
namespace {

std::string postgres_database(const TempDir&) {
  return cluster().fresh_store();
}

const Engine kPostgres{"postgres", &postgres_database};

DYNID_INSTANTIATE_STORE_CONTRACT(Postgres, kPostgres);

const RunKey kRun{"proto-17", "run-1"};

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Two servers' store clients (two connections) store the same run's chunks at once, every chunk
// sent by both, from opposite ends: every chunk is stored once (the other's copy is a
// duplicate), the ledger counts each exactly once, and no client's acknowledgement moves back.
TEST(StorePostgres, TwoClientsStoringOneRunAtOnceStoreEveryChunkOnce) {
  const std::string uri = cluster().fresh_store();
  Store(uri).add_run(announcement("proto-17", "run-1"));
  constexpr std::uint64_t kChunks = 16;
  std::uint64_t stored[2] = {0, 0};
  auto client = [&](int k) {
    Store store(uri);
    std::optional<std::uint64_t> acknowledged;
    for (std::uint64_t n = 0; n < kChunks; ++n) {
      const std::uint64_t sequence = k == 0 ? n : kChunks - 1 - n;  // from both ends
      const auto result = store.store_chunk(chunk("proto-17", "run-1", sequence));
      if (result.status == ChunkStatus::stored) ++stored[k];
      ASSERT_TRUE(result.status == ChunkStatus::stored || result.status == ChunkStatus::duplicate)
          << result.reason;
      EXPECT_GE(result.contiguous_through, acknowledged) << "client " << k << " #" << sequence;
      acknowledged = result.contiguous_through;
    }
  };
  std::thread first(client, 0);
  std::thread second(client, 1);
  first.join();
  second.join();
  EXPECT_EQ(stored[0] + stored[1], kChunks);
  Store store(uri);
  EXPECT_EQ(store.highest_contiguous(kRun), kChunks - 1);
  EXPECT_EQ(store.list_runs("proto-17").at(0).chunks_stored, kChunks);
  auto stream = store.chunks(kRun, 0, kChunks - 1);
  for (std::uint64_t s = 0; s < kChunks; ++s)
    EXPECT_TRUE(same(*stream.next(), chunk("proto-17", "run-1", s)));
}

// The run cache of one client does not hide what another did: a run closed through another
// connection takes no new chunk here.
TEST(StorePostgres, ARunClosedByAnotherClientTakesNoNewChunk) {
  const std::string uri = cluster().fresh_store();
  Store first(uri);
  first.add_run(announcement("proto-17", "run-1"));
  ASSERT_EQ(first.store_chunk(chunk("proto-17", "run-1", 0)).status, ChunkStatus::stored);
  Store(uri).close_run(kRun);
  EXPECT_THROW(first.store_chunk(chunk("proto-17", "run-1", 1)), InputError);
  EXPECT_EQ(first.store_chunk(chunk("proto-17", "run-1", 0)).status, ChunkStatus::duplicate);
  EXPECT_TRUE(first.list_runs("proto-17").at(0).closed);
}

// What store_chunk acknowledged survives the server's crash (an immediate stop: no shutdown
// checkpoint, recovery from the WAL). The restarted server keeps its port: the tests after this
// one connect as before.
TEST(StorePostgres, AcknowledgedChunksSurviveACrashOfTheServer) {
  const std::string uri = cluster().fresh_store();
  {
    Store store(uri);
    store.add_run(announcement("proto-17", "run-1"));
    for (std::uint64_t s = 0; s < 12; ++s)
      ASSERT_EQ(store.store_chunk(chunk("proto-17", "run-1", s)).contiguous_through, s);
    store.save_checkpoint(kRun, 5, "state after 0..5");
    cluster().crash_and_restart();
    EXPECT_THROW(store.highest_contiguous({"proto-17", "run-2"}), StoreError);  // connection lost
  }
  Store store(uri);
  EXPECT_EQ(store.highest_contiguous(kRun), 11u);
  EXPECT_EQ(store.latest_checkpoint(kRun)->state, "state after 0..5");
  auto stream = store.chunks(kRun, 6, 11);
  for (std::uint64_t s = 6; s < 12; ++s)
    EXPECT_TRUE(same(*stream.next(), chunk("proto-17", "run-1", s)));
}

TEST(StorePostgres, DatabasesThatAreNotOurStoreAreRefusedNamingThem) {
  const std::string foreign = cluster().fresh_store("foreign");
  cluster().sql(foreign, "CREATE TABLE chunks (id int)");
  try {
    Store store(foreign);
    FAIL() << "opened another application's database";
  } catch (const StoreError& e) {
    EXPECT_TRUE(contains(e.what(), foreign)) << e.what();
    EXPECT_TRUE(contains(e.what(), "not a dynid store")) << e.what();
  }

  const std::string newer = cluster().fresh_store("newer");
  Store{newer};
  cluster().sql(newer, "UPDATE dynid_schema SET version = 99");
  try {
    Store store(newer);
    FAIL() << "opened a database of a newer schema";
  } catch (const StoreError& e) {
    EXPECT_TRUE(contains(e.what(), "schema version 99")) << e.what();
  }
}

TEST(StorePostgres, AnUnreachableServerIsAClearErrorWithoutThePassword) {
  const std::string uri = "postgresql://dynid:hunter2@127.0.0.1:1/fleet?connect_timeout=2";
  try {
    Store store(uri);
    FAIL() << "connected to nothing";
  } catch (const StoreError& e) {
    EXPECT_TRUE(contains(e.what(), "postgresql://dynid:***@127.0.0.1:1/fleet")) << e.what();
    EXPECT_FALSE(contains(e.what(), "hunter2")) << e.what();
  }
}

// A server that does not fsync cannot make a chunk durable: the store refuses it rather than
// acknowledge chunks a power cut would lose.
TEST(StorePostgres, AServerWithoutFsyncIsRefused) {
  const std::string uri = cluster().fresh_store();
  cluster().sql(cluster().uri("postgres"), "ALTER SYSTEM SET fsync = off");
  cluster().sql(cluster().uri("postgres"), "SELECT pg_reload_conf(), pg_sleep(0.2)");
  std::string error;
  try {
    Store store(uri);
  } catch (const StoreError& e) {
    error = e.what();
  }
  cluster().sql(cluster().uri("postgres"), "ALTER SYSTEM RESET fsync");
  cluster().sql(cluster().uri("postgres"), "SELECT pg_reload_conf(), pg_sleep(0.2)");
  EXPECT_TRUE(contains(error, "fsync = off")) << error;
  Store store(uri);  // durable again: opens
}

}  // namespace
}  // namespace dynid::store::test
