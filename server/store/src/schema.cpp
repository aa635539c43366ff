#include "schema.hpp"

#include <array>
#include <string>

#include "dynid/store/errors.hpp"

namespace dynid::store::detail {

namespace {

// 'dyni' in ASCII: `file` and our open() recognise the database as a dynid store.
constexpr std::int64_t kApplicationId = 0x64796E69;

// Sequences are stored as SQLite integers (signed 64-bit); -1 in the ledger means "none yet".
// Timestamps are nanoseconds since the Unix epoch (system clock).
constexpr const char* kVersion1 = R"sql(
CREATE TABLE schema_version (
  version INTEGER NOT NULL
);
CREATE TABLE vehicles (
  id            INTEGER PRIMARY KEY,
  name          TEXT NOT NULL UNIQUE,
  first_seen_ns INTEGER NOT NULL
);
CREATE TABLE runs (
  id               INTEGER PRIMARY KEY,
  vehicle_id       INTEGER NOT NULL REFERENCES vehicles(id),
  name             TEXT NOT NULL,
  announcement     BLOB NOT NULL,
  announcement_crc INTEGER NOT NULL,
  announced_ns     INTEGER NOT NULL,
  closed_ns        INTEGER,
  UNIQUE (vehicle_id, name)
);
CREATE TABLE chunks (
  run_id             INTEGER NOT NULL REFERENCES runs(id),
  sequence           INTEGER NOT NULL CHECK (sequence >= 0),
  first_sample_index INTEGER NOT NULL,
  rows               INTEGER NOT NULL,
  bytes              BLOB NOT NULL,
  crc                INTEGER NOT NULL,
  stored_ns          INTEGER NOT NULL,
  PRIMARY KEY (run_id, sequence)
) WITHOUT ROWID;
CREATE TABLE ledger (
  run_id             INTEGER PRIMARY KEY REFERENCES runs(id),
  contiguous_through INTEGER NOT NULL DEFAULT -1,
  folded_through     INTEGER NOT NULL DEFAULT -1,
  CHECK (folded_through <= contiguous_through)
);
CREATE TABLE checkpoints (
  run_id         INTEGER NOT NULL REFERENCES runs(id),
  folded_through INTEGER NOT NULL CHECK (folded_through >= 0),
  state          BLOB NOT NULL,
  crc            INTEGER NOT NULL,
  created_ns     INTEGER NOT NULL,
  PRIMARY KEY (run_id, folded_through)
);
CREATE TABLE estimates (
  id         INTEGER PRIMARY KEY,
  vehicle_id INTEGER NOT NULL REFERENCES vehicles(id),
  model      TEXT NOT NULL,
  scope      TEXT NOT NULL,
  time_ns    INTEGER NOT NULL,
  encoded    BLOB NOT NULL,
  crc        INTEGER NOT NULL
);
CREATE INDEX estimates_by_vehicle_model ON estimates (vehicle_id, model, time_ns);
INSERT INTO schema_version (version) VALUES (1);
)sql";

// Version 2: chunks become a rowid table with a separate (run_id, sequence) index, the bytes
// last. In version 1's WITHOUT ROWID table every key comparison of a b-tree search read the
// whole row, a ~24 KB blob through its overflow pages, so each existence check of the ingest
// path copied ~100 KB; the index holds only the keys.
constexpr const char* kVersion2 = R"sql(
CREATE TABLE chunks_v2 (
  id                 INTEGER PRIMARY KEY,
  run_id             INTEGER NOT NULL REFERENCES runs(id),
  sequence           INTEGER NOT NULL CHECK (sequence >= 0),
  first_sample_index INTEGER NOT NULL,
  rows               INTEGER NOT NULL,
  crc                INTEGER NOT NULL,
  stored_ns          INTEGER NOT NULL,
  bytes              BLOB NOT NULL,
  UNIQUE (run_id, sequence)
);
INSERT INTO chunks_v2 (run_id, sequence, first_sample_index, rows, crc, stored_ns, bytes)
  SELECT run_id, sequence, first_sample_index, rows, crc, stored_ns, bytes FROM chunks
  ORDER BY run_id, sequence;
DROP TABLE chunks;
ALTER TABLE chunks_v2 RENAME TO chunks;
INSERT INTO schema_version (version) VALUES (2);
)sql";

// Version 3: leases (store.hpp, Leases): which server serves a vehicle until when.
constexpr const char* kVersion3 = R"sql(
CREATE TABLE leases (
  vehicle    TEXT PRIMARY KEY,
  holder     TEXT NOT NULL,
  expires_ns INTEGER NOT NULL
);
INSERT INTO schema_version (version) VALUES (3);
)sql";

// migrations[v] takes a file from version v to v + 1 (v = 0 is the empty file). A later
// version appends its script here and bumps kSchemaVersion; the script also updates
// schema_version.
constexpr std::array<const char*, kSchemaVersion> kMigrations = {kVersion1, kVersion2,
                                                                  kVersion3};

std::int64_t pragma_int(Database& db, const char* sql) {
  Statement statement(db, sql);
  return statement.step() ? statement.column_int(0) : 0;
}

bool has_table(Database& db, const char* name) {
  Statement statement(db, "SELECT 1 FROM sqlite_schema WHERE type = 'table' AND name = ?1");
  return statement.bind(1, std::string_view(name)).step();
}

int file_version(Database& db) {
  const std::int64_t application = pragma_int(db, "PRAGMA application_id");
  const bool empty = pragma_int(db, "SELECT count(*) FROM sqlite_schema") == 0;
  if (empty) return 0;
  if (application != kApplicationId || !has_table(db, "schema_version")) {
    throw StoreError("store " + db.path() +
                         ": not a dynid store (another application's SQLite "
                         "database)",
                     0);
  }
  return static_cast<int>(pragma_int(db, "SELECT max(version) FROM schema_version"));
}

}  // namespace

void bring_up_to_date(Database& db) {
  const int version = file_version(db);
  if (version > kSchemaVersion) {
    throw StoreError("store " + db.path() + ": schema version " + std::to_string(version) +
                         " was written by a newer dynid (this build knows up to " +
                         std::to_string(kSchemaVersion) + ")",
                     0);
  }
  for (int v = version; v < kSchemaVersion; ++v) {
    Transaction transaction(db);
    db.exec(kMigrations[static_cast<std::size_t>(v)], "migrate schema");
    // A constant, not input: the one place where SQL text is assembled.
    const std::string mark = "PRAGMA application_id = " + std::to_string(kApplicationId);
    db.exec(mark.c_str(), "set application id");
    transaction.commit();
  }
}

}  // namespace dynid::store::detail
