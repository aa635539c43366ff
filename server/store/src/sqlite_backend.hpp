#pragma once
// SqliteBackend: the store's rows in one SQLite file (WAL, synchronous=FULL), private to the
// store. It fulfils backend.hpp's contract with one connection: every statement prepared once
// when the store opens and reused by every call; a write transaction is BEGIN IMMEDIATE (so
// the run's ledger row is locked with the whole file, which one writer holds at a time);
// commits fsync the log; a thread of its own copies the log back into the file
// (wal_checkpointer.hpp). Opening runs the integrity check StoreOptions asks for. Leases
// expire on this machine's clock; the file's write lock keeps a lease from changing while a
// write that checked it is open.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backend.hpp"
#include "dynid/store/store.hpp"
#include "sqlite.hpp"
#include "wal_checkpointer.hpp"

namespace dynid::store::detail {

/// Opens the file's connection properly: pragmas, integrity check, schema.
struct Configured {
  Configured(Database& db, const StoreOptions& options);
};

class SqliteBackend final : public Backend {
 public:
  SqliteBackend(const std::string& path, const StoreOptions& options);

  const std::string& location() const override { return db_.path(); }
  const std::string& describe() const override { return name_; }
  std::unique_ptr<Transaction> begin() override;
  bool in_transaction() const override;

  std::optional<StoredRun> find_run(const RunKey& key) override;
  std::optional<std::int64_t> insert_run(const RunKey& key, const std::string& encoded,
                                         std::int64_t crc, std::int64_t now_ns) override;
  void close_run(std::int64_t run_id, std::int64_t now_ns) override;
  std::optional<std::int64_t> find_vehicle(const std::string& vehicle) override;
  std::vector<std::string> vehicles() override;
  std::vector<RunInfo> runs(std::int64_t vehicle_id) override;

  std::optional<Ledger> ledger(std::int64_t run_id) override;
  std::optional<std::string> chunk_bytes(std::int64_t run_id, std::int64_t sequence) override;
  void insert_chunk(std::int64_t run_id, const ChunkColumns& columns, std::string_view bytes,
                    std::int64_t now_ns) override;
  std::int64_t contiguous_from(std::int64_t run_id, std::int64_t from) override;
  void set_contiguous(std::int64_t run_id, std::int64_t mark) override;
  void set_folded(std::int64_t run_id, std::int64_t mark) override;
  void restart_folds(std::optional<std::int64_t> vehicle_id) override;
  std::unique_ptr<ChunkRows> chunk_rows(std::int64_t run_id, std::int64_t from,
                                        std::int64_t to) override;

  std::optional<StoredCheckpoint> newest_checkpoint(std::int64_t run_id) override;
  void replace_checkpoints(std::int64_t run_id, const StoredCheckpoint& checkpoint,
                           std::int64_t now_ns) override;
  void insert_estimate(std::int64_t vehicle_id, const EstimateRecord& estimate,
                       std::int64_t crc) override;
  std::vector<StoredEstimate> estimates(std::int64_t vehicle_id, const std::string& model) override;

  Lease acquire_lease(const std::string& vehicle, const std::string& holder,
                      std::int64_t ttl_ns) override;
  void release_lease(const std::string& vehicle, const std::string& holder) override;
  std::vector<Lease> leases() override;
  std::optional<LeaseState> lease_for_write(const std::string& vehicle) override;

 private:
  Database db_;
  std::string name_;
  Configured configured_;  // declared here: the statements below need the schema in place

  Statement insert_vehicle_{db_,
                            "INSERT INTO vehicles (name, first_seen_ns) VALUES (?1, ?2) "
                            "ON CONFLICT (name) DO NOTHING"};
  Statement find_vehicle_{db_, "SELECT id FROM vehicles WHERE name = ?1"};
  Statement find_run_{db_,
                      "SELECT r.id, r.announcement, r.announcement_crc, r.closed_ns FROM runs r "
                      "JOIN vehicles v ON v.id = r.vehicle_id WHERE v.name = ?1 AND r.name = ?2"};
  Statement insert_run_{db_,
                        "INSERT INTO runs (vehicle_id, name, announcement, announcement_crc, "
                        "announced_ns) VALUES ((SELECT id FROM vehicles WHERE name = ?1), ?2, ?3, "
                        "?4, ?5)"};
  Statement insert_ledger_{db_, "INSERT INTO ledger (run_id) VALUES (?1)"};
  Statement close_{db_, "UPDATE runs SET closed_ns = ?2 WHERE id = ?1 AND closed_ns IS NULL"};
  Statement find_chunk_{db_, "SELECT bytes FROM chunks WHERE run_id = ?1 AND sequence = ?2"};
  Statement chunk_exists_{db_, "SELECT 1 FROM chunks WHERE run_id = ?1 AND sequence = ?2"};
  Statement insert_chunk_{db_,
                          "INSERT INTO chunks (run_id, sequence, first_sample_index, rows, bytes, "
                          "crc, stored_ns) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)"};
  Statement read_ledger_{db_,
                         "SELECT l.contiguous_through, l.folded_through, r.closed_ns FROM ledger l "
                         "JOIN runs r ON r.id = l.run_id WHERE l.run_id = ?1"};
  Statement set_contiguous_{db_, "UPDATE ledger SET contiguous_through = ?2 WHERE run_id = ?1"};
  Statement set_folded_{db_, "UPDATE ledger SET folded_through = ?2 WHERE run_id = ?1"};
  // ?1 < 0: every run.
  Statement restart_folds_{db_,
                           "UPDATE ledger SET folded_through = coalesce((SELECT max(folded_through) "
                           "FROM checkpoints c WHERE c.run_id = ledger.run_id), -1) WHERE ?1 < 0 OR "
                           "run_id IN (SELECT id FROM runs WHERE vehicle_id = ?1)"};
  Statement newest_checkpoint_{db_,
                               "SELECT folded_through, state, crc FROM checkpoints WHERE run_id "
                               "= ?1 ORDER BY folded_through DESC LIMIT 1"};
  Statement insert_checkpoint_{db_,
                               "INSERT INTO checkpoints (run_id, folded_through, state, crc, "
                               "created_ns) VALUES (?1, ?2, ?3, ?4, ?5)"};
  Statement prune_checkpoints_{db_,
                               "DELETE FROM checkpoints WHERE run_id = ?1 AND folded_through < ?2"};
  Statement insert_estimate_{db_,
                             "INSERT INTO estimates (vehicle_id, model, scope, time_ns, encoded, "
                             "crc) VALUES (?1, ?2, ?3, ?4, ?5, ?6)"};
  Statement select_estimates_{db_,
                              "SELECT scope, time_ns, encoded, crc FROM estimates WHERE "
                              "vehicle_id = ?1 AND model = ?2 ORDER BY time_ns, id"};
  Statement select_vehicles_{db_, "SELECT name FROM vehicles ORDER BY name"};
  Statement select_runs_{db_,
                         "SELECT r.name, r.closed_ns, l.contiguous_through, l.folded_through, "
                         "(SELECT count(*) FROM chunks c WHERE c.run_id = r.id) FROM runs r "
                         "JOIN ledger l ON l.run_id = r.id WHERE r.vehicle_id = ?1 ORDER BY r.id"};

  // Leases, judged on this machine's clock (?4, ?2: now).
  Statement take_lease_{db_,
                        "INSERT INTO leases (vehicle, holder, expires_ns) VALUES (?1, ?2, ?3) "
                        "ON CONFLICT (vehicle) DO UPDATE SET holder = excluded.holder, "
                        "expires_ns = excluded.expires_ns "
                        "WHERE leases.holder = excluded.holder OR leases.expires_ns <= ?4"};
  Statement find_lease_{
      db_, "SELECT holder, expires_ns, expires_ns - ?2 FROM leases WHERE vehicle = ?1"};
  Statement drop_lease_{db_, "DELETE FROM leases WHERE vehicle = ?1 AND holder = ?2"};
  Statement select_leases_{db_, "SELECT vehicle, holder, expires_ns FROM leases ORDER BY vehicle"};

  // Last: destroyed first, before the connection it hooks (wal_checkpointer.hpp).
  WalCheckpointer checkpointer_{db_};
};

}  // namespace dynid::store::detail
