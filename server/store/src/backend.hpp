#pragma once
// Backend: the storage engine behind a Store, private to the store. Store (store.hpp) owns the
// rules (ordering window, duplicates and conflicts, ledger marks, checkpoint rules, CRC checks,
// the run cache); a Backend only reads and writes rows, in the transactions Store opens.
//
// Contract, for every implementation (SQLite: sqlite_backend.hpp; PostgreSQL:
// postgres_backend.hpp):
// - Opening brings the schema up to date (creating it on first use, versioned) and resets every
//   run's folded mark to its newest checkpoint (store.hpp, Folding).
// - begin() opens a write transaction; inside an open one (Store::batch) it is a savepoint. A
//   Transaction destroyed without commit() rolls back its own part and never throws. commit()
//   of an outer transaction returns only once the writes are durable (store.hpp, Durability).
// - ledger() inside a transaction locks the run's ledger row until the transaction ends, so
//   two writers of the same run (two connections, two processes) are serialised, never
//   interleaved.
// - Failures of the engine are StoreError/CorruptionError naming describe(); no row is ever
//   half-written.
// - Sequences and marks are signed 64-bit integers; -1 means "none yet" (support.hpp).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/store/store.hpp"

namespace dynid::store::detail {

/// A runs row: the encoded announcement and its CRC as stored, unchecked.
struct StoredRun {
  std::int64_t id = 0;
  std::string encoded;
  std::int64_t crc = 0;
  bool closed = false;
};

struct Ledger {
  std::int64_t contiguous = -1;
  std::int64_t folded = -1;
  bool closed = false;  ///< the run's, read with the ledger: another client may have closed it
};

struct StoredCheckpoint {
  std::int64_t folded_through = 0;
  std::string state;
  std::int64_t crc = 0;
};

/// An estimates row, oldest first in estimates().
struct StoredEstimate {
  std::string scope;
  std::int64_t time_ns = 0;
  std::string encoded;
  std::int64_t crc = 0;
};

/// A chunks row's columns besides its bytes: a second, independent record of what was stored,
/// which ChunkStream checks the decoded bytes against.
struct ChunkColumns {
  std::int64_t sequence = 0;
  std::int64_t first_sample_index = 0;
  std::int64_t rows = 0;
  std::int64_t crc = 0;
};

/// A lease as a write finds it: remaining_ns > 0 while it has not expired (on the clock that
/// judges expiry: store.hpp, Leases).
struct LeaseState {
  Lease lease;
  std::int64_t remaining_ns = 0;
};

struct ChunkRow {
  ChunkColumns columns;
  std::string bytes;
};

/// The chunk rows of one run over a range, in sequence order, read a bounded number at a time.
class ChunkRows {
 public:
  virtual ~ChunkRows() = default;
  /// The next row, or std::nullopt past the last stored one of the range.
  virtual std::optional<ChunkRow> next() = 0;
  /// Ends the read early (releases what the engine holds for it); next() is not called again.
  virtual void release() = 0;
};

class Backend {
 public:
  class Transaction {
   public:
    virtual ~Transaction() = default;
    virtual void commit() = 0;
  };

  virtual ~Backend() = default;

  /// The location as given to Store (a path or a URI).
  virtual const std::string& location() const = 0;
  /// What messages call it: "store <path>", a URI without its password.
  virtual const std::string& describe() const = 0;

  virtual std::unique_ptr<Transaction> begin() = 0;
  virtual bool in_transaction() const = 0;

  // ---- vehicles and runs ----
  virtual std::optional<StoredRun> find_run(const RunKey& key) = 0;
  /// Inserts the vehicle if new, the run and its empty ledger row; returns the run's id, or
  /// std::nullopt when the run exists already (inserted meanwhile by another connection).
  virtual std::optional<std::int64_t> insert_run(const RunKey& key, const std::string& encoded,
                                                 std::int64_t crc, std::int64_t now_ns) = 0;
  virtual void close_run(std::int64_t run_id, std::int64_t now_ns) = 0;
  virtual std::optional<std::int64_t> find_vehicle(const std::string& vehicle) = 0;
  virtual std::vector<std::string> vehicles() = 0;
  virtual std::vector<RunInfo> runs(std::int64_t vehicle_id) = 0;

  // ---- chunks and the ledger ----
  /// The run's ledger row and whether the run is closed (the ledger row locked until the
  /// transaction ends, inside one); nullopt if missing.
  virtual std::optional<Ledger> ledger(std::int64_t run_id) = 0;
  virtual std::optional<std::string> chunk_bytes(std::int64_t run_id, std::int64_t sequence) = 0;
  virtual void insert_chunk(std::int64_t run_id, const ChunkColumns& columns,
                            std::string_view bytes, std::int64_t now_ns) = 0;
  /// The end of the stored run of sequences that starts at `from` (itself stored).
  virtual std::int64_t contiguous_from(std::int64_t run_id, std::int64_t from) = 0;
  virtual void set_contiguous(std::int64_t run_id, std::int64_t mark) = 0;
  virtual void set_folded(std::int64_t run_id, std::int64_t mark) = 0;
  /// Every run's folded mark back to its newest checkpoint (-1 without one): the vehicle's runs,
  /// or every run when vehicle_id is nullopt.
  virtual void restart_folds(std::optional<std::int64_t> vehicle_id) = 0;
  virtual std::unique_ptr<ChunkRows> chunk_rows(std::int64_t run_id, std::int64_t from,
                                                std::int64_t to) = 0;

  // ---- checkpoints and estimates ----
  virtual std::optional<StoredCheckpoint> newest_checkpoint(std::int64_t run_id) = 0;
  /// Inserts the checkpoint and deletes the run's older ones.
  virtual void replace_checkpoints(std::int64_t run_id, const StoredCheckpoint& checkpoint,
                                   std::int64_t now_ns) = 0;
  virtual void insert_estimate(std::int64_t vehicle_id, const EstimateRecord& estimate,
                               std::int64_t crc) = 0;
  virtual std::vector<StoredEstimate> estimates(std::int64_t vehicle_id,
                                                const std::string& model) = 0;

  // ---- leases (store.hpp, Leases; inside a transaction the Store opens) ----
  /// Takes the lease if free or expired, renews it if holder's; returns it as it stands.
  virtual Lease acquire_lease(const std::string& vehicle, const std::string& holder,
                              std::int64_t ttl_ns) = 0;
  virtual void release_lease(const std::string& vehicle, const std::string& holder) = 0;
  virtual std::vector<Lease> leases() = 0;
  /// The vehicle's lease, kept from changing until the transaction ends (a takeover waits).
  virtual std::optional<LeaseState> lease_for_write(const std::string& vehicle) = 0;
};

/// The backend for a location: a postgresql:// (or postgres://) URI opens PostgreSQL, anything
/// else is an SQLite file path.
std::unique_ptr<Backend> open_backend(const std::string& location, const StoreOptions& options);

}  // namespace dynid::store::detail
