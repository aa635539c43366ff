// Faults on real SQLite files: a process killed with SIGKILL while storing, corrupted pages and
// rows, a full disk, files that are not ours. (Bad input, which must change nothing on every
// backend, is in the contract suite: test_store_bad_input.cpp.)
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "dynid/error.hpp"
#include "dynid/store/store.hpp"
#include "store_test_support.hpp"

namespace dynid::store {
namespace {

using test::announcement;
using test::chunk;

const RunKey kRun{"proto-17", "run-1"};

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Runs SQL on the file through a connection of the test's own (to set a file up, or look at it).
void raw_sql(const std::string& path, const char* sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* message = nullptr;
  const int rc = sqlite3_exec(db, sql, nullptr, nullptr, &message);
  EXPECT_EQ(rc, SQLITE_OK) << (message ? message : "");
  sqlite3_free(message);
  sqlite3_close(db);
}

std::int64_t raw_int(const std::string& path, const char* sql) {
  sqlite3* db = nullptr;
  sqlite3_stmt* statement = nullptr;
  std::int64_t value = -1;
  if (sqlite3_open(path.c_str(), &db) == SQLITE_OK &&
      sqlite3_prepare_v2(db, sql, -1, &statement, nullptr) == SQLITE_OK &&
      sqlite3_step(statement) == SQLITE_ROW) {
    value = sqlite3_column_int64(statement, 0);
  }
  sqlite3_finalize(statement);
  sqlite3_close(db);
  return value;
}

// ---- crash -----------------------------------------------------------------------------

// The child stores chunks from the run's next sequence on, writing each acknowledged
// sequence to `ack` after store_chunk returned, until it is killed.
[[noreturn]] void store_until_killed(const std::string& path, int ack) {
  alarm(60);  // never outlive a broken parent
  try {
    Store store(path);
    const auto contiguous = store.highest_contiguous(kRun);
    std::uint64_t next = contiguous ? *contiguous + 1 : 0;
    for (int n = 0; n < 100000; ++n, ++next) {
      if (store.store_chunk(chunk("proto-17", "run-1", next, 50)).status != ChunkStatus::stored) {
        _exit(3);
      }
      if (write(ack, &next, sizeof next) != sizeof next) _exit(4);
    }
  } catch (...) {
    _exit(2);
  }
  _exit(0);
}

// Reads acknowledgements until `wanted` arrived (then kills the child) or EOF; returns the
// highest acknowledged sequence, -1 for none.
std::int64_t collect_acks_then_kill(pid_t child, int ack, int wanted) {
  std::int64_t highest = -1;
  int count = 0;
  bool killed = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (;;) {
    if (!killed && (count >= wanted || std::chrono::steady_clock::now() > deadline)) {
      kill(child, SIGKILL);
      killed = true;
    }
    pollfd p{ack, POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    std::uint64_t sequence = 0;
    if (read(ack, &sequence, sizeof sequence) != sizeof sequence) break;  // EOF: child gone
    highest = std::max(highest, static_cast<std::int64_t>(sequence));
    ++count;
  }
  if (!killed) kill(child, SIGKILL);
  return highest;
}

TEST(StoreCrash, EveryAcknowledgedChunkSurvivesSigkillMidStream) {
  test::TempDir dir;
  const std::string path = dir.file("store.db");
  Store(path).add_run(announcement("proto-17", "run-1"));
  std::int64_t acknowledged = -1;
  for (int wanted : {25, 7, 40}) {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      close(fds[0]);
      store_until_killed(path, fds[1]);
    }
    close(fds[1]);
    const std::int64_t highest = collect_acks_then_kill(child, fds[0], wanted);
    close(fds[0]);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
        << "the child ended on its own, status " << status;
    ASSERT_GT(highest, acknowledged) << "the child acknowledged nothing new";
    acknowledged = highest;

    Store store(path);
    EXPECT_EQ(raw_int(path, "SELECT journal_mode = 'wal' FROM pragma_journal_mode"), 1);
    const auto contiguous = store.highest_contiguous(kRun);
    ASSERT_TRUE(contiguous.has_value());
    EXPECT_GE(static_cast<std::int64_t>(*contiguous), acknowledged);
    auto stream = store.chunks(kRun, 0, *contiguous);
    for (std::uint64_t s = 0; s <= *contiguous; ++s) {
      const auto c = stream.next();
      ASSERT_TRUE(c.has_value());
      ASSERT_TRUE(test::same(*c, chunk("proto-17", "run-1", s, 50))) << "chunk " << s;
    }
  }
}

// ---- corruption --------------------------------------------------------------------------

TEST(StoreCorruption, DamagedPageIsReportedOnOpenNamingTheFile) {
  test::TempDir dir;
  const std::string path = dir.file("store.db");
  {
    Store store(path);
    store.add_run(announcement("proto-17", "run-1"));
    for (std::uint64_t s = 0; s < 200; ++s) store.store_chunk(chunk("proto-17", "run-1", s));
  }
  // The root of the chunks b-tree (an interior page by now): an invalid page type and garbage.
  const std::int64_t root =
      raw_int(path, "SELECT rootpage FROM sqlite_schema WHERE name = 'chunks'");
  const std::int64_t page_size = raw_int(path, "PRAGMA page_size");
  ASSERT_GT(root, 1);
  test::overwrite(path, static_cast<std::uint64_t>((root - 1) * page_size),
                  std::string(64, '\x2a'));
  try {
    Store damaged(path);
    FAIL() << "a damaged file opened without complaint";
  } catch (const CorruptionError& e) {
    EXPECT_TRUE(contains(e.what(), path)) << e.what();
  }
}

TEST(StoreCorruption, DamagedChunkOrCheckpointIsReportedWhenReadNeverUsed) {
  test::TempDir dir;
  const std::string path = dir.file("store.db");
  const std::string state = "checkpoint-state-" + std::string(200, 'S');
  {
    Store store(path);
    store.add_run(announcement("proto-17", "run-1"));
    for (std::uint64_t s = 0; s < 5; ++s) store.store_chunk(chunk("proto-17", "run-1", s));
    store.save_checkpoint(kRun, 4, state);
  }  // closed: the log is checkpointed into the file
  const std::string bytes = ingest::encode_chunk(chunk("proto-17", "run-1", 2));
  const std::uint64_t at = test::find_in_file(path, bytes) + bytes.size() / 2;
  test::overwrite(path, at, "\x7f");
  test::overwrite(path, test::find_in_file(path, state) + 100, "X");

  Store store(path);  // the pages are well-formed: only the checksums can tell
  auto stream = store.chunks(kRun, 0, 4);
  EXPECT_TRUE(stream.next().has_value());
  EXPECT_TRUE(stream.next().has_value());
  try {
    stream.next();
    FAIL() << "a damaged chunk was handed out";
  } catch (const CorruptionError& e) {
    EXPECT_TRUE(contains(e.what(), "proto-17/run-1#2")) << e.what();
    EXPECT_TRUE(contains(e.what(), path)) << e.what();
  }
  try {
    store.latest_checkpoint(kRun);
    FAIL() << "a damaged checkpoint was handed out";
  } catch (const CorruptionError& e) {
    EXPECT_TRUE(contains(e.what(), "proto-17/run-1")) << e.what();
  }
}

TEST(StoreCorruption, FilesThatAreNotOurStoreAreRefusedNamingTheFile) {
  test::TempDir dir;
  const std::string garbage = dir.file("garbage.db");
  {
    std::string noise(8192, '\0');
    for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = static_cast<char>(i * 131 + 7);
    std::FILE* f = std::fopen(garbage.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fwrite(noise.data(), 1, noise.size(), f);
    std::fclose(f);
  }
  try {
    Store store(garbage);
    FAIL() << "opened a file of noise";
  } catch (const StoreError& e) {
    EXPECT_TRUE(contains(e.what(), garbage)) << e.what();
  }

  const std::string other = dir.file("other.db");
  raw_sql(other, "CREATE TABLE songs (title TEXT)");
  try {
    Store store(other);
    FAIL() << "opened another application's database";
  } catch (const StoreError& e) {
    EXPECT_TRUE(contains(e.what(), other) && contains(e.what(), "not a dynid store")) << e.what();
  }

  const std::string newer = dir.file("newer.db");
  Store(newer).add_run(announcement("proto-17", "run-1"));
  raw_sql(newer, "UPDATE schema_version SET version = 99");
  try {
    Store store(newer);
    FAIL() << "opened a file of a newer schema";
  } catch (const StoreError& e) {
    EXPECT_TRUE(contains(e.what(), newer) && contains(e.what(), "newer")) << e.what();
  }
}

// ---- schema migration ------------------------------------------------------------------

// Rebuilds the chunks table in version 1's layout (WITHOUT ROWID, bytes inline in the key's
// b-tree) and marks the file version 1, as a store written before the migration existed.
void downgrade_to_version_1(const std::string& path) {
  raw_sql(path,
          "BEGIN;"
          "CREATE TABLE chunks_v1 (run_id INTEGER NOT NULL REFERENCES runs(id),"
          " sequence INTEGER NOT NULL CHECK (sequence >= 0), first_sample_index INTEGER NOT NULL,"
          " rows INTEGER NOT NULL, bytes BLOB NOT NULL, crc INTEGER NOT NULL,"
          " stored_ns INTEGER NOT NULL, PRIMARY KEY (run_id, sequence)) WITHOUT ROWID;"
          "INSERT INTO chunks_v1 SELECT run_id, sequence, first_sample_index, rows, bytes, crc,"
          " stored_ns FROM chunks;"
          "DROP TABLE chunks; ALTER TABLE chunks_v1 RENAME TO chunks; DROP TABLE leases;"
          "DELETE FROM schema_version WHERE version > 1; COMMIT;");
}

TEST(StoreSchema, VersionOneFileIsMigratedKeepingEveryChunkAndItsLedger) {
  test::TempDir dir;
  const std::string path = dir.file("store.db");
  {
    Store store(path);
    store.add_run(announcement("proto-17", "run-1"));
    for (std::uint64_t s : {0, 1, 2, 4}) store.store_chunk(chunk("proto-17", "run-1", s));
  }
  downgrade_to_version_1(path);
  ASSERT_EQ(raw_int(path, "SELECT max(version) FROM schema_version"), 1);
  ASSERT_EQ(raw_int(path, "SELECT count(*) FROM sqlite_schema WHERE name = 'chunks' AND "
                          "sql LIKE '%WITHOUT ROWID%'"),
            1);

  Store store(path);
  EXPECT_EQ(raw_int(path, "SELECT max(version) FROM schema_version"), 3);
  EXPECT_EQ(raw_int(path, "SELECT count(*) FROM sqlite_schema WHERE name = 'chunks' AND "
                          "sql LIKE '%WITHOUT ROWID%'"),
            0);
  EXPECT_EQ(store.highest_contiguous(kRun), 2u);
  // The chunk stored ahead of the gap is still there: filling the gap reaches it.
  EXPECT_EQ(store.store_chunk(chunk("proto-17", "run-1", 3)).status, ChunkStatus::stored);
  EXPECT_EQ(store.highest_contiguous(kRun), 4u);
  EXPECT_EQ(store.store_chunk(chunk("proto-17", "run-1", 1)).status, ChunkStatus::duplicate);
  EXPECT_EQ(store.store_chunk(chunk("proto-17", "run-1", 1, 10, 1)).status, ChunkStatus::conflict);
  auto stream = store.chunks(kRun, 0, 4);
  for (std::uint64_t s = 0; s <= 4; ++s) {
    const auto c = stream.next();
    ASSERT_TRUE(c.has_value());
    EXPECT_TRUE(test::same(*c, chunk("proto-17", "run-1", s))) << "chunk " << s;
  }
}

// ---- full disk ---------------------------------------------------------------------------

TEST(StoreFullDisk, FullFileIsAClearErrorAndStoresNoPartOfTheChunk) {
  test::TempDir dir;
  const std::string path = dir.file("store.db");
  Store(path).add_run(announcement("proto-17", "run-1"));
  StoreOptions capped;
  capped.max_pages = static_cast<std::int64_t>(std::filesystem::file_size(path) / 4096) + 30;
  std::uint64_t failed = 0;
  {
    Store store(path, capped);
    bool full = false;
    for (std::uint64_t s = 0; s < 200 && !full; ++s) {
      try {
        ASSERT_EQ(store.store_chunk(chunk("proto-17", "run-1", s, 400)).status,
                  ChunkStatus::stored);
      } catch (const StoreError& e) {
        full = true;
        failed = s;
        EXPECT_EQ(e.code() & 0xff, SQLITE_FULL) << e.what();
        EXPECT_TRUE(contains(e.what(), path) && contains(e.what(), "full")) << e.what();
      }
    }
    ASSERT_TRUE(full) << "the cap was never reached";
    ASSERT_GT(failed, 0u);
    EXPECT_EQ(store.highest_contiguous(kRun), failed - 1);
    EXPECT_EQ(store.list_runs("proto-17").at(0).chunks_stored, failed);
    EXPECT_THROW(store.store_chunk(chunk("proto-17", "run-1", failed, 400)), StoreError);
    // Space for other work is still there: a small write after the failure goes through.
    store.mark_folded(kRun, 0);
  }
  Store store(path);  // no cap: the disk was "freed"
  EXPECT_EQ(store.highest_contiguous(kRun), failed - 1);
  auto stream = store.chunks(kRun, 0, failed - 1);
  for (std::uint64_t s = 0; s < failed; ++s) {
    EXPECT_TRUE(test::same(*stream.next(), chunk("proto-17", "run-1", s, 400))) << s;
  }
  EXPECT_EQ(store.store_chunk(chunk("proto-17", "run-1", failed, 400)).status, ChunkStatus::stored);
}

}  // namespace
}  // namespace dynid::store
