#include "sqlite_backend.hpp"

#include <sqlite3.h>

#include <utility>

#include "schema.hpp"
#include "support.hpp"

namespace dynid::store::detail {

namespace {

const char* check_pragma(StoreOptions::Check check) {
  return check == StoreOptions::Check::full ? "PRAGMA integrity_check" : "PRAGMA quick_check";
}

// Runs quick_check/integrity_check; anything but a single "ok" names the file and SQLite's
// first findings.
void check_file(Database& db, StoreOptions::Check check) {
  if (check == StoreOptions::Check::none) return;
  Statement statement(db, check_pragma(check));
  std::string findings;
  while (statement.step()) {
    const std::string line = statement.column_text(0);
    if (line == "ok") continue;
    if (findings.size() < 500) findings += (findings.empty() ? "" : "; ") + line;
  }
  if (!findings.empty()) {
    throw CorruptionError(
        "store " + db.path() + ": " + check_pragma(check) + " failed: " + findings, 0);
  }
}

// Switches to WAL and returns the journal mode now in force.
std::string wal_mode(Database& db) {
  Statement statement(db, "PRAGMA journal_mode = WAL");
  return statement.step() ? statement.column_text(0) : std::string();
}

void configure(Database& db, const StoreOptions& options) {
  // The busy timeout first: the other pragmas may have to wait for a lock.
  const std::string busy = "PRAGMA busy_timeout = " + std::to_string(options.busy_timeout_ms);
  db.exec(busy.c_str(), "set busy timeout");
  if (wal_mode(db) != "wal") {
    throw StoreError("store " + db.path() + ": cannot switch to WAL mode", 0);
  }
  // FULL: in WAL mode, every COMMIT fsyncs the log before returning (see store.hpp).
  db.exec("PRAGMA synchronous = FULL", "set synchronous");
  db.exec("PRAGMA foreign_keys = ON", "enable foreign keys");
  if (options.max_pages > 0) {
    const std::string cap = "PRAGMA max_page_count = " + std::to_string(options.max_pages);
    db.exec(cap.c_str(), "cap the file size");
  }
  check_file(db, options.check_on_open);
  bring_up_to_date(db);
}

}  // namespace

Configured::Configured(Database& db, const StoreOptions& options) {
  configure(db, options);
}

// ---- transactions ----------------------------------------------------------------------

namespace {

class SqliteTransaction final : public Backend::Transaction {
 public:
  explicit SqliteTransaction(Database& db) : transaction_(db) {}
  void commit() override { transaction_.commit(); }

 private:
  detail::Transaction transaction_;
};

// The rows of a range, read one at a time through the store's connection.
class SqliteChunkRows final : public ChunkRows {
 public:
  SqliteChunkRows(Database& db, std::int64_t run_id, std::int64_t from, std::int64_t to)
      : select_(db,
                "SELECT sequence, first_sample_index, rows, crc, bytes FROM chunks "
                "WHERE run_id = ?1 AND sequence BETWEEN ?2 AND ?3 ORDER BY sequence") {
    select_.start().bind(1, run_id).bind(2, from).bind(3, to);
  }
  std::optional<ChunkRow> next() override {
    if (!select_.step()) return std::nullopt;
    return ChunkRow{{select_.column_int(0), select_.column_int(1), select_.column_int(2),
                     select_.column_int(3)},
                    select_.column_blob(4)};
  }
  void release() override { select_.start(); }

 private:
  Statement select_;
};

}  // namespace

SqliteBackend::SqliteBackend(const std::string& path, const StoreOptions& options)
    : db_(path, true), name_("store " + path), configured_(db_, options) {}

std::unique_ptr<Backend::Transaction> SqliteBackend::begin() {
  return std::make_unique<SqliteTransaction>(db_);
}

bool SqliteBackend::in_transaction() const {
  return sqlite3_get_autocommit(db_.handle()) == 0;
}

// ---- vehicles and runs ------------------------------------------------------------------

std::optional<StoredRun> SqliteBackend::find_run(const RunKey& key) {
  Query query(find_run_);
  if (!query->bind(1, key.vehicle).bind(2, key.run).step()) return std::nullopt;
  return StoredRun{query->column_int(0), query->column_blob(1), query->column_int(2),
                   !query->column_is_null(3)};
}

std::optional<std::int64_t> SqliteBackend::insert_run(const RunKey& key, const std::string& encoded,
                                                      std::int64_t crc, std::int64_t now_ns) {
  insert_vehicle_.start().bind(1, key.vehicle).bind(2, now_ns).run();
  insert_run_.start()
      .bind(1, key.vehicle)
      .bind(2, key.run)
      .bind_blob(3, encoded)
      .bind(4, crc)
      .bind(5, now_ns)
      .run();
  const std::int64_t run_id = db_.last_insert_rowid();
  insert_ledger_.start().bind(1, run_id).run();
  return run_id;
}

void SqliteBackend::close_run(std::int64_t run_id, std::int64_t now_ns) {
  close_.start().bind(1, run_id).bind(2, now_ns).run();
}

std::optional<std::int64_t> SqliteBackend::find_vehicle(const std::string& vehicle) {
  Query query(find_vehicle_);
  if (!query->bind(1, vehicle).step()) return std::nullopt;
  return query->column_int(0);
}

std::vector<std::string> SqliteBackend::vehicles() {
  std::vector<std::string> names;
  for (select_vehicles_.start(); select_vehicles_.step();)
    names.push_back(select_vehicles_.column_text(0));
  return names;
}

std::vector<RunInfo> SqliteBackend::runs(std::int64_t vehicle_id) {
  Statement& select = select_runs_;
  select.start().bind(1, vehicle_id);
  std::vector<RunInfo> runs;
  while (select.step()) {
    runs.push_back({select.column_text(0), !select.column_is_null(1), from_db(select.column_int(2)),
                    from_db(select.column_int(3)),
                    static_cast<std::uint64_t>(select.column_int(4))});
  }
  return runs;
}

// ---- chunks and the ledger --------------------------------------------------------------

std::optional<Ledger> SqliteBackend::ledger(std::int64_t run_id) {
  Query query(read_ledger_);
  if (!query->bind(1, run_id).step()) return std::nullopt;
  return Ledger{query->column_int(0), query->column_int(1), !query->column_is_null(2)};
}

std::optional<std::string> SqliteBackend::chunk_bytes(std::int64_t run_id, std::int64_t sequence) {
  Query query(find_chunk_);
  if (!query->bind(1, run_id).bind(2, sequence).step()) return std::nullopt;
  return query->column_blob(0);
}

void SqliteBackend::insert_chunk(std::int64_t run_id, const ChunkColumns& columns,
                                 std::string_view bytes, std::int64_t now_ns) {
  insert_chunk_.start()
      .bind(1, run_id)
      .bind(2, columns.sequence)
      .bind(3, columns.first_sample_index)
      .bind(4, columns.rows)
      .bind_blob(5, bytes)
      .bind(6, columns.crc)
      .bind(7, now_ns)
      .run();
}

// One indexed existence check per chunk held ahead of the gap (at most the reorder window).
std::int64_t SqliteBackend::contiguous_from(std::int64_t run_id, std::int64_t from) {
  std::int64_t last = from;
  Query query(chunk_exists_);
  while (query->start().bind(1, run_id).bind(2, last + 1).step()) ++last;
  return last;
}

void SqliteBackend::set_contiguous(std::int64_t run_id, std::int64_t mark) {
  set_contiguous_.start().bind(1, run_id).bind(2, mark).run();
}

void SqliteBackend::set_folded(std::int64_t run_id, std::int64_t mark) {
  set_folded_.start().bind(1, run_id).bind(2, mark).run();
}

void SqliteBackend::restart_folds(std::optional<std::int64_t> vehicle_id) {
  restart_folds_.start().bind(1, vehicle_id.value_or(-1)).run();
}

std::unique_ptr<ChunkRows> SqliteBackend::chunk_rows(std::int64_t run_id, std::int64_t from,
                                                     std::int64_t to) {
  return std::make_unique<SqliteChunkRows>(db_, run_id, from, to);
}

// ---- checkpoints and estimates ----------------------------------------------------------

std::optional<StoredCheckpoint> SqliteBackend::newest_checkpoint(std::int64_t run_id) {
  Query query(newest_checkpoint_);
  if (!query->bind(1, run_id).step()) return std::nullopt;
  return StoredCheckpoint{query->column_int(0), query->column_blob(1), query->column_int(2)};
}

void SqliteBackend::replace_checkpoints(std::int64_t run_id, const StoredCheckpoint& checkpoint,
                                        std::int64_t now_ns) {
  insert_checkpoint_.start()
      .bind(1, run_id)
      .bind(2, checkpoint.folded_through)
      .bind_blob(3, checkpoint.state)
      .bind(4, checkpoint.crc)
      .bind(5, now_ns)
      .run();
  prune_checkpoints_.start().bind(1, run_id).bind(2, checkpoint.folded_through).run();
}

void SqliteBackend::insert_estimate(std::int64_t vehicle_id, const EstimateRecord& estimate,
                                    std::int64_t crc) {
  insert_estimate_.start()
      .bind(1, vehicle_id)
      .bind(2, estimate.model)
      .bind(3, estimate.scope)
      .bind(4, estimate.time_ns)
      .bind_blob(5, estimate.encoded)
      .bind(6, crc)
      .run();
}

std::vector<StoredEstimate> SqliteBackend::estimates(std::int64_t vehicle_id,
                                                     const std::string& model) {
  Query select(select_estimates_);
  select->bind(1, vehicle_id).bind(2, model);
  std::vector<StoredEstimate> rows;
  while (select->step()) {
    rows.push_back({select->column_text(0), select->column_int(1), select->column_blob(2),
                    select->column_int(3)});
  }
  return rows;
}

// ---- leases ------------------------------------------------------------------------------

Lease SqliteBackend::acquire_lease(const std::string& vehicle, const std::string& holder,
                                   std::int64_t ttl_ns) {
  const std::int64_t now = now_ns();
  take_lease_.start().bind(1, vehicle).bind(2, holder).bind(3, now + ttl_ns).bind(4, now).run();
  return lease_for_write(vehicle).value().lease;
}

void SqliteBackend::release_lease(const std::string& vehicle, const std::string& holder) {
  drop_lease_.start().bind(1, vehicle).bind(2, holder).run();
}

std::vector<Lease> SqliteBackend::leases() {
  std::vector<Lease> all;
  for (select_leases_.start(); select_leases_.step();) {
    all.push_back({select_leases_.column_text(0), select_leases_.column_text(1),
                   select_leases_.column_int(2)});
  }
  return all;
}

// The file's write lock, held by the transaction, already keeps the lease from changing.
std::optional<LeaseState> SqliteBackend::lease_for_write(const std::string& vehicle) {
  Query query(find_lease_);
  if (!query->bind(1, vehicle).bind(2, now_ns()).step()) return std::nullopt;
  return LeaseState{{vehicle, query->column_text(0), query->column_int(1)}, query->column_int(2)};
}

}  // namespace dynid::store::detail
