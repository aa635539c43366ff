#pragma once
// The state behind a Store, private to the store: the connection, the prepared statements
// (prepared once when the store opens, reused by every call), and a cache of the runs looked
// up so that store_chunk does not decode the announcement again for every chunk.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "dynid/store/store.hpp"
#include "sqlite.hpp"
#include "wal_checkpointer.hpp"

namespace dynid::store {

namespace detail {

/// Opens the file's connection properly: pragmas, integrity check, schema, folded marks.
struct Configured {
  Configured(Database& db, const StoreOptions& options);
};

struct RunRow {
  std::int64_t id = 0;
  ingest::RunAnnouncement announcement;
  std::string encoded;
  bool closed = false;
};

struct Ledger {
  std::int64_t contiguous = -1;
  std::int64_t folded = -1;
};

}  // namespace detail

struct Store::Impl {
  Impl(const std::string& path, StoreOptions store_options)
      : db(path, true), options(std::move(store_options)), configured(db, options) {}

  detail::Database db;
  StoreOptions options;
  detail::Configured configured;  // declared here: the statements below need the schema in place
  std::map<RunKey, detail::RunRow> runs;  // cache of runs looked up; written only after a commit

  detail::Statement insert_vehicle{db,
                                   "INSERT INTO vehicles (name, first_seen_ns) VALUES (?1, ?2) "
                                   "ON CONFLICT (name) DO NOTHING"};
  detail::Statement find_vehicle{db, "SELECT id FROM vehicles WHERE name = ?1"};
  detail::Statement find_run{
      db,
      "SELECT r.id, r.announcement, r.announcement_crc, r.closed_ns FROM runs r "
      "JOIN vehicles v ON v.id = r.vehicle_id WHERE v.name = ?1 AND r.name = ?2"};
  detail::Statement insert_run{
      db,
      "INSERT INTO runs (vehicle_id, name, announcement, announcement_crc, "
      "announced_ns) VALUES ((SELECT id FROM vehicles WHERE name = ?1), ?2, ?3, "
      "?4, ?5)"};
  detail::Statement insert_ledger{db, "INSERT INTO ledger (run_id) VALUES (?1)"};
  detail::Statement close{db, "UPDATE runs SET closed_ns = ?2 WHERE id = ?1 AND closed_ns IS NULL"};
  detail::Statement find_chunk{db, "SELECT bytes FROM chunks WHERE run_id = ?1 AND sequence = ?2"};
  detail::Statement chunk_exists{db, "SELECT 1 FROM chunks WHERE run_id = ?1 AND sequence = ?2"};
  detail::Statement insert_chunk{
      db,
      "INSERT INTO chunks (run_id, sequence, first_sample_index, rows, bytes, "
      "crc, stored_ns) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)"};
  detail::Statement read_ledger{
      db, "SELECT contiguous_through, folded_through FROM ledger WHERE run_id = ?1"};
  detail::Statement set_contiguous{db,
                                   "UPDATE ledger SET contiguous_through = ?2 WHERE run_id = ?1"};
  detail::Statement set_folded{db, "UPDATE ledger SET folded_through = ?2 WHERE run_id = ?1"};
  detail::Statement newest_checkpoint{
      db,
      "SELECT folded_through, state, crc FROM checkpoints WHERE run_id "
      "= ?1 ORDER BY folded_through DESC LIMIT 1"};
  detail::Statement insert_checkpoint{
      db,
      "INSERT INTO checkpoints (run_id, folded_through, state, crc, "
      "created_ns) VALUES (?1, ?2, ?3, ?4, ?5)"};
  detail::Statement prune_checkpoints{
      db, "DELETE FROM checkpoints WHERE run_id = ?1 AND folded_through < ?2"};
  detail::Statement insert_estimate{
      db,
      "INSERT INTO estimates (vehicle_id, model, scope, time_ns, encoded, "
      "crc) VALUES (?1, ?2, ?3, ?4, ?5, ?6)"};
  detail::Statement select_estimates{db,
                                     "SELECT scope, time_ns, encoded, crc FROM estimates WHERE "
                                     "vehicle_id = ?1 AND model = ?2 ORDER BY time_ns, id"};
  detail::Statement select_vehicles{db, "SELECT name FROM vehicles ORDER BY name"};
  detail::Statement select_runs{
      db,
      "SELECT r.name, r.closed_ns, l.contiguous_through, l.folded_through, "
      "(SELECT count(*) FROM chunks c WHERE c.run_id = r.id) FROM runs r "
      "JOIN ledger l ON l.run_id = r.id WHERE r.vehicle_id = ?1 ORDER BY r.id"};

  // Last: destroyed first, before the connection it hooks (wal_checkpointer.hpp).
  detail::WalCheckpointer checkpointer{db};

  /// The run, from the cache or the file (then cached); nullptr if never announced.
  const detail::RunRow* lookup(const RunKey& key);
  const detail::RunRow& run(const RunKey& key);
  std::int64_t vehicle_id(const std::string& vehicle);
  detail::Ledger ledger(std::int64_t run_id);
  std::int64_t advance_contiguous(std::int64_t run_id, std::int64_t from);
  std::optional<std::string> stored_bytes(std::int64_t run_id, std::uint64_t sequence);
  void insert(const detail::RunRow& run, const ingest::Chunk& chunk, const std::string& bytes);
  /// store_chunk after validation; `bytes` is encode_chunk(chunk) (Ordering in store.hpp).
  StoreChunkResult store_valid(const detail::RunRow& run, const ingest::Chunk& chunk,
                               const std::string& bytes);
};

}  // namespace dynid::store
