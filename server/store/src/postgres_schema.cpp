#include "postgres_schema.hpp"

#include <array>
#include <string>

#include "dynid/store/errors.hpp"

namespace dynid::store::detail::postgres {

namespace {

// The same tables as the SQLite store's schema (schema.cpp, its version 2), in PostgreSQL's
// types: every integer is a bigint (sequences, -1 for "none yet" in the ledger; timestamps in
// nanoseconds since the Unix epoch; CRC-32s), every blob a bytea. Chunks are stored out of line
// uncompressed (STORAGE EXTERNAL): measured doubles do not compress, and trying costs CPU on
// every insert.
constexpr const char* kVersion1 = R"sql(
CREATE TABLE dynid_schema (
  version BIGINT NOT NULL
);
CREATE TABLE vehicles (
  id            BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
  name          TEXT NOT NULL UNIQUE,
  first_seen_ns BIGINT NOT NULL
);
CREATE TABLE runs (
  id               BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
  vehicle_id       BIGINT NOT NULL REFERENCES vehicles(id),
  name             TEXT NOT NULL,
  announcement     BYTEA NOT NULL,
  announcement_crc BIGINT NOT NULL,
  announced_ns     BIGINT NOT NULL,
  closed_ns        BIGINT,
  UNIQUE (vehicle_id, name)
);
CREATE TABLE chunks (
  run_id             BIGINT NOT NULL REFERENCES runs(id),
  sequence           BIGINT NOT NULL CHECK (sequence >= 0),
  first_sample_index BIGINT NOT NULL,
  rows               BIGINT NOT NULL,
  crc                BIGINT NOT NULL,
  stored_ns          BIGINT NOT NULL,
  bytes              BYTEA NOT NULL,
  PRIMARY KEY (run_id, sequence)
);
ALTER TABLE chunks ALTER COLUMN bytes SET STORAGE EXTERNAL;
CREATE TABLE ledger (
  run_id             BIGINT PRIMARY KEY REFERENCES runs(id),
  contiguous_through BIGINT NOT NULL DEFAULT -1,
  folded_through     BIGINT NOT NULL DEFAULT -1,
  CHECK (folded_through <= contiguous_through)
);
CREATE TABLE checkpoints (
  run_id         BIGINT NOT NULL REFERENCES runs(id),
  folded_through BIGINT NOT NULL CHECK (folded_through >= 0),
  state          BYTEA NOT NULL,
  crc            BIGINT NOT NULL,
  created_ns     BIGINT NOT NULL,
  PRIMARY KEY (run_id, folded_through)
);
CREATE TABLE estimates (
  id         BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
  vehicle_id BIGINT NOT NULL REFERENCES vehicles(id),
  model      TEXT NOT NULL,
  scope      TEXT NOT NULL,
  time_ns    BIGINT NOT NULL,
  encoded    BYTEA NOT NULL,
  crc        BIGINT NOT NULL
);
CREATE INDEX estimates_by_vehicle_model ON estimates (vehicle_id, model, time_ns);
INSERT INTO dynid_schema (version) VALUES (1);
)sql";

// Version 2: leases (store.hpp, Leases): which server serves a vehicle until when, on the
// database server's clock.
constexpr const char* kVersion2 = R"sql(
CREATE TABLE leases (
  vehicle    TEXT PRIMARY KEY,
  holder     TEXT NOT NULL,
  expires_ns BIGINT NOT NULL
);
CREATE FUNCTION dynid_now_ns() RETURNS BIGINT LANGUAGE sql VOLATILE
  AS $$ SELECT (extract(epoch FROM clock_timestamp()) * 1000000000)::bigint $$;
INSERT INTO dynid_schema (version) VALUES (2);
)sql";

// migrations[v] takes a database from version v to v + 1 (v = 0 is a database without our
// tables). A later version appends its script and bumps kSchemaVersion; the script also
// records its version in dynid_schema.
constexpr std::array<const char*, kSchemaVersion> kMigrations = {kVersion1, kVersion2};

// 'dyni' in ASCII, as the SQLite store's application id: the advisory lock of migrations.
constexpr const char* kLockMigrations = "SELECT pg_advisory_xact_lock(1685682025)";

// Tables of ours by name in the current schema, found without a dynid_schema table: another
// application's database.
constexpr const char* kForeignTables =
    "SELECT string_agg(table_name::text, ', ' ORDER BY table_name) FROM information_schema.tables "
    "WHERE table_schema = current_schema() AND table_name IN ('vehicles', 'runs', 'chunks', "
    "'ledger', 'checkpoints', 'estimates')";

int database_version(pq::Connection& connection) {
  const pq::Params none;
  if (connection.run("SELECT to_regclass('dynid_schema')::text", none).is_null(0, 0)) {
    const pq::Result foreign = connection.run(kForeignTables, none);
    if (foreign.is_null(0, 0)) return 0;
    throw StoreError(connection.name() + ": not a dynid store (another application's tables: " +
                         foreign.bytes(0, 0) + ")",
                     0);
  }
  const pq::Result version = connection.run("SELECT max(version) FROM dynid_schema", none);
  if (version.is_null(0, 0)) {
    throw StoreError(connection.name() + ": dynid_schema holds no version (damaged schema)", 0);
  }
  return static_cast<int>(version.i64(0, 0));
}

}  // namespace

void bring_up_to_date(pq::Connection& connection) {
  pq::Transaction transaction(connection);
  connection.exec(kLockMigrations, "lock the schema for migration");
  const int version = database_version(connection);
  if (version > kSchemaVersion) {
    throw StoreError(connection.name() + ": schema version " + std::to_string(version) +
                         " was written by a newer dynid (this build knows up to " +
                         std::to_string(kSchemaVersion) + ")",
                     0);
  }
  for (int v = version; v < kSchemaVersion; ++v)
    connection.exec(kMigrations[static_cast<std::size_t>(v)], "migrate schema");
  transaction.commit();
}

}  // namespace dynid::store::detail::postgres
