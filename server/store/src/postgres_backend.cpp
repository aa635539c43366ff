#include "postgres_backend.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include "dynid/store/location.hpp"
#include "postgres_schema.hpp"
#include "support.hpp"

namespace dynid::store::detail {

namespace {

using pq::Params;

// ---- the statements (parameters are $n, typed by Params) ----

constexpr const char* kFindRun =
    "SELECT r.id, r.announcement, r.announcement_crc, r.closed_ns FROM runs r "
    "JOIN vehicles v ON v.id = r.vehicle_id WHERE v.name = $1 AND r.name = $2";
constexpr const char* kInsertVehicle =
    "INSERT INTO vehicles (name, first_seen_ns) VALUES ($1, $2) ON CONFLICT (name) DO NOTHING";
// DO NOTHING + RETURNING: no row when another connection added the run meanwhile.
constexpr const char* kInsertRun =
    "INSERT INTO runs (vehicle_id, name, announcement, announcement_crc, announced_ns) "
    "VALUES ((SELECT id FROM vehicles WHERE name = $1), $2, $3, $4, $5) "
    "ON CONFLICT (vehicle_id, name) DO NOTHING RETURNING id";
constexpr const char* kInsertLedger = "INSERT INTO ledger (run_id) VALUES ($1)";
constexpr const char* kCloseRun =
    "UPDATE runs SET closed_ns = $2 WHERE id = $1 AND closed_ns IS NULL";
constexpr const char* kFindVehicle = "SELECT id FROM vehicles WHERE name = $1";
// COLLATE "C": names sort byte by byte, as SQLite sorts them, whatever the database's locale.
constexpr const char* kVehicles = "SELECT name FROM vehicles ORDER BY name COLLATE \"C\"";
constexpr const char* kRuns =
    "SELECT r.name, r.closed_ns, l.contiguous_through, l.folded_through, "
    "(SELECT count(*) FROM chunks c WHERE c.run_id = r.id) FROM runs r "
    "JOIN ledger l ON l.run_id = r.id WHERE r.vehicle_id = $1 ORDER BY r.id";

const std::string kLedger =
    "SELECT l.contiguous_through, l.folded_through, r.closed_ns FROM ledger l "
    "JOIN runs r ON r.id = l.run_id WHERE l.run_id = $1";
// Locks the ledger row alone: the run's writes queue on it (postgres_backend.hpp, Isolation).
// Plain reads outside a transaction lock nothing (a row lock is a write of the row).
const std::string kLedgerForUpdate = kLedger + " FOR UPDATE OF l";
constexpr const char* kChunkBytes = "SELECT bytes FROM chunks WHERE run_id = $1 AND sequence = $2";
constexpr const char* kInsertChunk =
    "INSERT INTO chunks (run_id, sequence, first_sample_index, rows, crc, stored_ns, bytes) "
    "VALUES ($1, $2, $3, $4, $5, $6, $7)";
// The last stored sequence from $2 on whose successor is missing: the end of the stored run of
// sequences that starts at $2 (one query, however many chunks were held ahead of the gap).
constexpr const char* kContiguousFrom =
    "SELECT min(c.sequence) FROM chunks c WHERE c.run_id = $1 AND c.sequence >= $2 AND NOT "
    "EXISTS (SELECT 1 FROM chunks d WHERE d.run_id = $1 AND d.sequence = c.sequence + 1)";
constexpr const char* kSetContiguous =
    "UPDATE ledger SET contiguous_through = $2 WHERE run_id = $1";
constexpr const char* kSetFolded = "UPDATE ledger SET folded_through = $2 WHERE run_id = $1";
constexpr const char* kChunkRows =
    "SELECT sequence, first_sample_index, rows, crc, bytes FROM chunks "
    "WHERE run_id = $1 AND sequence BETWEEN $2 AND $3 ORDER BY sequence LIMIT $4";

constexpr const char* kNewestCheckpoint =
    "SELECT folded_through, state, crc FROM checkpoints WHERE run_id = $1 "
    "ORDER BY folded_through DESC LIMIT 1";
constexpr const char* kInsertCheckpoint =
    "INSERT INTO checkpoints (run_id, folded_through, state, crc, created_ns) "
    "VALUES ($1, $2, $3, $4, $5)";
constexpr const char* kPruneCheckpoints =
    "DELETE FROM checkpoints WHERE run_id = $1 AND folded_through < $2";
constexpr const char* kInsertEstimate =
    "INSERT INTO estimates (vehicle_id, model, scope, time_ns, encoded, crc) "
    "VALUES ($1, $2, $3, $4, $5, $6)";
constexpr const char* kEstimates =
    "SELECT scope, time_ns, encoded, crc FROM estimates WHERE vehicle_id = $1 AND model = $2 "
    "ORDER BY time_ns, id";

// Leases are judged on the database server's clock (dynid_now_ns(), postgres_schema.cpp), so
// servers whose clocks differ agree.
constexpr const char* kTakeLease =
    "INSERT INTO leases AS l (vehicle, holder, expires_ns) VALUES ($1, $2, dynid_now_ns() + $3) "
    "ON CONFLICT (vehicle) DO UPDATE SET holder = excluded.holder, "
    "expires_ns = excluded.expires_ns WHERE l.holder = excluded.holder OR "
    "l.expires_ns <= dynid_now_ns()";
// FOR SHARE: a takeover (the upsert above) waits until the writes that checked it commit.
constexpr const char* kLeaseForWrite =
    "SELECT holder, expires_ns, expires_ns - dynid_now_ns() FROM leases WHERE vehicle = $1 "
    "FOR SHARE";
constexpr const char* kDropLease = "DELETE FROM leases WHERE vehicle = $1 AND holder = $2";
constexpr const char* kLeases =
    "SELECT vehicle, holder, expires_ns FROM leases ORDER BY vehicle COLLATE \"C\"";

// $1 < 0: every run.
constexpr const char* kRestartFolds =
    "UPDATE ledger SET folded_through = coalesce((SELECT max(folded_through) FROM checkpoints c "
    "WHERE c.run_id = ledger.run_id), -1) WHERE $1 < 0 OR "
    "run_id IN (SELECT id FROM runs WHERE vehicle_id = $1)";

class PostgresTransaction final : public Backend::Transaction {
 public:
  explicit PostgresTransaction(pq::Connection& connection) : transaction_(connection) {}
  void commit() override { transaction_.commit(); }

 private:
  pq::Transaction transaction_;
};

// The rows of a range, fetched kReplayBatch at a time, so a replay never holds a whole run.
class PostgresChunkRows final : public ChunkRows {
 public:
  PostgresChunkRows(pq::Connection& connection, std::int64_t run_id, std::int64_t from,
                    std::int64_t to)
      : connection_(connection), run_id_(run_id), next_(from), to_(to) {}

  std::optional<ChunkRow> next() override {
    if (index_ == batch_.size()) fetch();
    if (index_ == batch_.size()) return std::nullopt;
    return std::move(batch_[index_++]);
  }
  void release() override {
    batch_.clear();
    index_ = 0;
    next_ = to_ + 1;
  }

 private:
  void fetch() {
    batch_.clear();
    index_ = 0;
    if (next_ > to_) return;
    const pq::Result rows = connection_.run(
        kChunkRows, Params().i64(run_id_).i64(next_).i64(to_).i64(PostgresBackend::kReplayBatch));
    for (int r = 0; r < rows.rows(); ++r) {
      batch_.push_back(
          {{rows.i64(r, 0), rows.i64(r, 1), rows.i64(r, 2), rows.i64(r, 3)}, rows.bytes(r, 4)});
    }
    // Past the last row fetched; a short batch means the range holds no more rows.
    next_ = batch_.empty() || rows.rows() < PostgresBackend::kReplayBatch
                ? to_ + 1
                : batch_.back().columns.sequence + 1;
  }

  pq::Connection& connection_;
  std::int64_t run_id_;
  std::int64_t next_;
  std::int64_t to_;
  std::vector<ChunkRow> batch_;
  std::size_t index_ = 0;
};

std::optional<std::int64_t> first_i64(const pq::Result& result) {
  if (result.rows() == 0 || result.is_null(0, 0)) return std::nullopt;
  return result.i64(0, 0);
}

// Durable commits (see postgres_backend.hpp); notices off; waits for locks bounded.
void configure_session(pq::Connection& connection, const StoreOptions& options) {
  connection.exec("SET synchronous_commit = on", "set synchronous_commit");
  connection.exec("SET client_min_messages = warning", "set client_min_messages");
  // A number, not input: the one place where SQL text is assembled.
  const std::string lock_timeout =
      "SET lock_timeout = " + std::to_string(std::max(options.busy_timeout_ms, 0));
  connection.exec(lock_timeout.c_str(), "set lock_timeout");
  const pq::Result fsync = connection.run("SELECT current_setting('fsync')", Params());
  if (fsync.bytes(0, 0) != "on") {
    throw StoreError(connection.name() +
                         ": the server runs with fsync = off, so its commits are not durable; "
                         "the store needs fsync = on",
                     0);
  }
}

}  // namespace

PostgresBackend::PostgresBackend(const std::string& uri, const StoreOptions& options)
    : uri_(uri), connection_(uri, "store " + for_messages(uri)) {
  configure_session(connection_, options);
  postgres::bring_up_to_date(connection_);
}

std::unique_ptr<Backend::Transaction> PostgresBackend::begin() {
  return std::make_unique<PostgresTransaction>(connection_);
}

// ---- vehicles and runs ------------------------------------------------------------------

std::optional<StoredRun> PostgresBackend::find_run(const RunKey& key) {
  const pq::Result row = connection_.run(kFindRun, Params().text(key.vehicle).text(key.run));
  if (row.rows() == 0) return std::nullopt;
  return StoredRun{row.i64(0, 0), row.bytes(0, 1), row.i64(0, 2), !row.is_null(0, 3)};
}

std::optional<std::int64_t> PostgresBackend::insert_run(const RunKey& key,
                                                        const std::string& encoded,
                                                        std::int64_t crc, std::int64_t now_ns) {
  connection_.run(kInsertVehicle, Params().text(key.vehicle).i64(now_ns));
  const auto run_id = first_i64(connection_.run(
      kInsertRun, Params().text(key.vehicle).text(key.run).bytes(encoded).i64(crc).i64(now_ns)));
  if (run_id) connection_.run(kInsertLedger, Params().i64(*run_id));
  return run_id;
}

void PostgresBackend::close_run(std::int64_t run_id, std::int64_t now_ns) {
  connection_.run(kCloseRun, Params().i64(run_id).i64(now_ns));
}

std::optional<std::int64_t> PostgresBackend::find_vehicle(const std::string& vehicle) {
  return first_i64(connection_.run(kFindVehicle, Params().text(vehicle)));
}

std::vector<std::string> PostgresBackend::vehicles() {
  const pq::Result rows = connection_.run(kVehicles, Params());
  std::vector<std::string> names;
  for (int r = 0; r < rows.rows(); ++r) names.push_back(rows.bytes(r, 0));
  return names;
}

std::vector<RunInfo> PostgresBackend::runs(std::int64_t vehicle_id) {
  const pq::Result rows = connection_.run(kRuns, Params().i64(vehicle_id));
  std::vector<RunInfo> runs;
  for (int r = 0; r < rows.rows(); ++r) {
    runs.push_back({rows.bytes(r, 0), !rows.is_null(r, 1), from_db(rows.i64(r, 2)),
                    from_db(rows.i64(r, 3)), static_cast<std::uint64_t>(rows.i64(r, 4))});
  }
  return runs;
}

// ---- chunks and the ledger --------------------------------------------------------------

std::optional<Ledger> PostgresBackend::ledger(std::int64_t run_id) {
  const pq::Result row = connection_.run(
      (connection_.in_transaction() ? kLedgerForUpdate : kLedger).c_str(), Params().i64(run_id));
  if (row.rows() == 0) return std::nullopt;
  return Ledger{row.i64(0, 0), row.i64(0, 1), !row.is_null(0, 2)};
}

std::optional<std::string> PostgresBackend::chunk_bytes(std::int64_t run_id,
                                                        std::int64_t sequence) {
  const pq::Result row = connection_.run(kChunkBytes, Params().i64(run_id).i64(sequence));
  if (row.rows() == 0) return std::nullopt;
  return row.bytes(0, 0);
}

void PostgresBackend::insert_chunk(std::int64_t run_id, const ChunkColumns& columns,
                                   std::string_view bytes, std::int64_t now_ns) {
  connection_.run(kInsertChunk, Params()
                                    .i64(run_id)
                                    .i64(columns.sequence)
                                    .i64(columns.first_sample_index)
                                    .i64(columns.rows)
                                    .i64(columns.crc)
                                    .i64(now_ns)
                                    .bytes(bytes));
}

std::int64_t PostgresBackend::contiguous_from(std::int64_t run_id, std::int64_t from) {
  return first_i64(connection_.run(kContiguousFrom, Params().i64(run_id).i64(from))).value_or(from);
}

void PostgresBackend::set_contiguous(std::int64_t run_id, std::int64_t mark) {
  connection_.run(kSetContiguous, Params().i64(run_id).i64(mark));
}

void PostgresBackend::set_folded(std::int64_t run_id, std::int64_t mark) {
  connection_.run(kSetFolded, Params().i64(run_id).i64(mark));
}

void PostgresBackend::restart_folds(std::optional<std::int64_t> vehicle_id) {
  connection_.run(kRestartFolds, Params().i64(vehicle_id.value_or(-1)));
}

std::unique_ptr<ChunkRows> PostgresBackend::chunk_rows(std::int64_t run_id, std::int64_t from,
                                                       std::int64_t to) {
  return std::make_unique<PostgresChunkRows>(connection_, run_id, from, to);
}

// ---- checkpoints and estimates ----------------------------------------------------------

std::optional<StoredCheckpoint> PostgresBackend::newest_checkpoint(std::int64_t run_id) {
  const pq::Result row = connection_.run(kNewestCheckpoint, Params().i64(run_id));
  if (row.rows() == 0) return std::nullopt;
  return StoredCheckpoint{row.i64(0, 0), row.bytes(0, 1), row.i64(0, 2)};
}

void PostgresBackend::replace_checkpoints(std::int64_t run_id, const StoredCheckpoint& checkpoint,
                                          std::int64_t now_ns) {
  connection_.run(kInsertCheckpoint, Params()
                                         .i64(run_id)
                                         .i64(checkpoint.folded_through)
                                         .bytes(checkpoint.state)
                                         .i64(checkpoint.crc)
                                         .i64(now_ns));
  connection_.run(kPruneCheckpoints, Params().i64(run_id).i64(checkpoint.folded_through));
}

void PostgresBackend::insert_estimate(std::int64_t vehicle_id, const EstimateRecord& estimate,
                                      std::int64_t crc) {
  connection_.run(kInsertEstimate, Params()
                                       .i64(vehicle_id)
                                       .text(estimate.model)
                                       .text(estimate.scope)
                                       .i64(estimate.time_ns)
                                       .bytes(estimate.encoded)
                                       .i64(crc));
}

std::vector<StoredEstimate> PostgresBackend::estimates(std::int64_t vehicle_id,
                                                       const std::string& model) {
  const pq::Result rows = connection_.run(kEstimates, Params().i64(vehicle_id).text(model));
  std::vector<StoredEstimate> history;
  for (int r = 0; r < rows.rows(); ++r)
    history.push_back({rows.bytes(r, 0), rows.i64(r, 1), rows.bytes(r, 2), rows.i64(r, 3)});
  return history;
}

// ---- leases ------------------------------------------------------------------------------

Lease PostgresBackend::acquire_lease(const std::string& vehicle, const std::string& holder,
                                     std::int64_t ttl_ns) {
  connection_.run(kTakeLease, Params().text(vehicle).text(holder).i64(ttl_ns));
  return lease_for_write(vehicle).value().lease;
}

void PostgresBackend::release_lease(const std::string& vehicle, const std::string& holder) {
  connection_.run(kDropLease, Params().text(vehicle).text(holder));
}

std::vector<Lease> PostgresBackend::leases() {
  const pq::Result rows = connection_.run(kLeases, Params());
  std::vector<Lease> all;
  for (int r = 0; r < rows.rows(); ++r)
    all.push_back({rows.bytes(r, 0), rows.bytes(r, 1), rows.i64(r, 2)});
  return all;
}

std::optional<LeaseState> PostgresBackend::lease_for_write(const std::string& vehicle) {
  const pq::Result row = connection_.run(kLeaseForWrite, Params().text(vehicle));
  if (row.rows() == 0) return std::nullopt;
  return LeaseState{{vehicle, row.bytes(0, 0), row.i64(0, 1)}, row.i64(0, 2)};
}

}  // namespace dynid::store::detail
