#pragma once
// PostgresBackend: the store's rows in a PostgreSQL database, through libpq (pq.hpp), private to
// the store. It fulfils backend.hpp's contract with one connection per Store:
// - Durability: the session runs with synchronous_commit = on, so COMMIT returns only once the
//   transaction's WAL is flushed to disk on the server; a server running with fsync = off is
//   refused on open (its commits would not survive a power cut). A chunk is therefore durable
//   when store_chunk() returns, as with SQLite.
// - Isolation: transactions are READ COMMITTED; ledger() inside one takes the run's ledger row
//   FOR UPDATE, so every write of one run (from any number of servers) is serialised on that
//   row, and the unique key (run_id, sequence) makes a chunk stored at most once whatever else
//   goes wrong.
// - Reads of a replay fetch a bounded batch of chunks at a time (kReplayBatch).
// - Leases (store.hpp) expire on the database server's clock (dynid_now_ns(), schema version
//   2), so servers whose clocks differ agree; a fenced write reads the lease FOR SHARE, so a
//   takeover (an upsert of the lease row) waits until that write has committed.
// - Opening resets every run's folded mark to its checkpoint (store.hpp, Folding), as SQLite's
//   does: right for one server per database. With several servers sharing one, this must
//   become per vehicle, when a server takes a vehicle's lease over (issue 20: not yet).
// - StoreOptions: busy_timeout_ms becomes the session's lock_timeout; check_on_open and
//   max_pages are SQLite's and do nothing here (the server checks its own pages; every blob
//   still carries the store's CRC-32, checked on every read).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backend.hpp"
#include "dynid/store/store.hpp"
#include "pq.hpp"

namespace dynid::store::detail {

class PostgresBackend final : public Backend {
 public:
  static constexpr int kReplayBatch = 16;

  PostgresBackend(const std::string& uri, const StoreOptions& options);

  const std::string& location() const override { return uri_; }
  const std::string& describe() const override { return connection_.name(); }
  std::unique_ptr<Transaction> begin() override;
  bool in_transaction() const override { return connection_.in_transaction(); }

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
  std::string uri_;
  pq::Connection connection_;
};

}  // namespace dynid::store::detail
