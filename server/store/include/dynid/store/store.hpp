#pragma once
// Store: the server's durable archive of vehicles, run announcements, raw chunks (the source of
// truth), the per-run ledger, accumulator checkpoints and estimate history.
//
// Backends. The location names where (location.hpp): a file path is one SQLite file, the
// embedded default for one server; a postgresql:// URI is a PostgreSQL database. Every rule
// below holds for both; what differs is said where it does. The rules live here, once; a
// backend only reads and writes rows (src/backend.hpp).
//
// Durability. SQLite: the file is in WAL mode with synchronous=FULL on every commit: a write
// function that returns has had its transaction appended to the write-ahead log and fsync'd.
// PostgreSQL: the session runs with synchronous_commit = on, so a commit returns once the
// server has flushed its WAL, and a server running with fsync = off is refused on open. So once
// store_chunk() returns `stored` or `duplicate`, the chunk survives a crash of the process
// (SIGKILL included) and of the operating system or a power cut, as far as the disk honours
// fsync. That is the point at which the server may acknowledge it, and the only one. Every
// write path is one transaction (SQLite: BEGIN IMMEDIATE ... COMMIT; PostgreSQL: BEGIN ...
// COMMIT with the run's ledger row locked, so several servers writing one run are serialised):
// a write that throws has been rolled back and leaves nothing half-written. A full disk
// (SQLITE_FULL; PostgreSQL's SQLSTATE 53100), an I/O error or a lost connection is a StoreError
// naming the location; the chunk is then not stored and must not be acknowledged.
//
// Group commit (batch). batch(f) runs f inside one transaction: every write f makes is then a
// savepoint of it (a write that throws is rolled back alone, as above; the others stay), and
// all of them become durable together, with one fsync, when batch() returns. Inside a batch a
// write that returned is NOT durable yet: acknowledge nothing before batch() has returned. If
// f throws, or the commit fails (StoreError), everything f wrote is rolled back.
//
// Ordering (store_chunk). Sequences of a run start at 0. The ledger keeps the highest
// *contiguous* sequence stored: every sequence 0..c is stored. The acknowledgement is that c,
// never a sequence past a gap. A chunk past the gap (a resend overtook a lost chunk) is stored
// ahead if its sequence is below c + 1 + reorder_window, so the car's later resend of the
// missing chunk closes the gap and c jumps over everything already held; farther ahead it is
// refused (`beyond_window`, nothing stored) and the car resends it later from its spool. The
// window bounds what a misbehaving car can park in a gap. A chunk already stored with the same
// bytes is `duplicate` (fine: re-acknowledge, e.g. after a lost acknowledgement); with other
// bytes it is `conflict` (nothing changes; the stored chunk stays the truth).
//
// Folding. The ledger also keeps the highest sequence folded into the live accumulators
// (mark_folded, monotonic, never past c). A checkpoint is the accumulators' state after folding
// 0..folded_through; it is saved together with the ledger's folded mark in one transaction.
// In-memory folds do not survive their process: restart = latest_checkpoint(), then replay
// chunks(folded_through + 1, highest_contiguous()), the folded mark first set back to the
// checkpoint (or none). With one server per store opening the store does that for every run.
// In a shared store (StoreOptions::shared or holder) the other servers' folds are alive, so
// opening changes nothing: a server calls restart_folds(vehicle) when it takes a vehicle's
// lease, for that vehicle's runs only. Nothing is lost, nothing folded twice.
// Only a run's newest checkpoint is kept. A damaged one is reported (CorruptionError), and the
// run can still be rebuilt by replaying its chunks from #0.
//
// Integrity. On open, SQLite's PRAGMA quick_check (or integrity_check, or none: StoreOptions)
// must pass, else CorruptionError naming the file (PostgreSQL checks its own pages; data it
// reports damaged, SQLSTATE XX001/XX002, is a CorruptionError too). Every blob carries a CRC-32 that is checked when it
// is read back (a chunk's is its own checksum, kept in the row and inside the bytes, checked by
// decode_chunk; the decoded ids, sequence, grid index and row count must match the row too): a
// damaged row is reported as CorruptionError naming the file and vehicle/run/sequence, never
// used.
//
// Bad input (errors.hpp): an unknown run or vehicle, an announcement that conflicts with the
// stored one, a chunk that fails ingest::validate_chunk against its announcement, a new chunk
// for a closed run, a ledger mark that would fold twice or fold what is not stored: InputError
// naming what and why, and no state changes.
//
// Leases (issue 20: several servers sharing one database). A lease says which server (its
// holder id) serves a vehicle until when. acquire_lease() takes a vehicle's lease when it is free
// or expired, or renews it for its holder; release_lease() gives it up at once (a server that
// stops). Expiry is judged on one clock: the database server's for PostgreSQL, this machine's
// for SQLite. A store opened with StoreOptions::holder set is fenced: every write of a vehicle's
// data (add_run, store_chunk, mark_folded, save_checkpoint, record_estimate, close_run) first
// checks, inside its own transaction, that the holder holds the vehicle's unexpired lease, else
// it is NotHolderError (errors.hpp) and writes nothing. In PostgreSQL the check locks the lease
// row (FOR SHARE) until the write commits, so a takeover waits for the old holder's writes in
// flight and the old holder writes nothing after it: no chunk is stored or folded by two
// servers. With holder empty (the default, one server per store) nothing is checked.
//
// One Store per location and process (the server owns it); not thread-safe: one thread at a
// time. (Two Stores on one location, e.g. two servers' clients in a test, are serialised by
// the database: SQLite's file lock, PostgreSQL's row locks.)
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/ingest/validated_chunk.hpp"
#include "dynid/store/chunk_stream.hpp"
#include "dynid/store/errors.hpp"

namespace dynid::store {

struct RunKey {
  std::string vehicle;
  std::string run;
  auto operator<=>(const RunKey&) const = default;
};

struct StoreOptions {
  enum class Check { none, quick, full };
  /// What to verify on open: quick_check (O(file), skips index/content cross-checks) by default.
  /// SQLite only.
  Check check_on_open = Check::quick;
  /// A chunk is stored if its sequence < highest contiguous + 1 + reorder_window (>= 1; 1 means
  /// strictly in order).
  std::uint64_t reorder_window = 256;
  /// Passed to ingest::validate_chunk.
  ingest::ChunkLimits limits;
  /// How long to wait for a lock held by another connection before SQLITE_BUSY (PostgreSQL:
  /// the session's lock_timeout).
  int busy_timeout_ms = 5000;
  /// A cap on the file's size in pages (PRAGMA max_page_count; 0 keeps SQLite's). Reaching it
  /// behaves exactly like a full disk: SQLITE_FULL, a StoreError, nothing stored. SQLite only.
  std::int64_t max_pages = 0;
  /// The server id whose leases fence this store's writes (Leases above); empty: no fencing.
  std::string holder;
  /// Several servers use this store under leases, this connection unfenced or not (a server's
  /// lease keeper reads and takes leases without a holder). A store opened with a holder is
  /// shared whatever this says. Opening a store that is not shared sets every run's folded
  /// mark back to its checkpoint (Folding above).
  bool shared = false;
};

enum class ChunkStatus {
  stored,         ///< newly stored (in order or ahead of a gap)
  duplicate,      ///< already stored with the same bytes
  conflict,       ///< already stored with other bytes; nothing changed
  beyond_window,  ///< too far past the contiguous prefix; nothing stored
};

struct StoreChunkResult {
  ChunkStatus status = ChunkStatus::stored;
  /// The acknowledgement: every sequence 0..contiguous_through of the run is durably stored.
  std::optional<std::uint64_t> contiguous_through;
  /// Why, for conflict and beyond_window.
  std::string reason;
};

enum class AddRunResult { added, already_known };

struct RunInfo {
  std::string run;
  bool closed = false;
  std::optional<std::uint64_t> contiguous_through;
  std::optional<std::uint64_t> folded_through;
  std::uint64_t chunks_stored = 0;  ///< including chunks stored ahead of a gap
};

struct Checkpoint {
  std::uint64_t folded_through = 0;  ///< state = accumulators after folding 0..folded_through
  std::string state;
};

struct Lease {
  std::string vehicle;
  std::string holder;
  std::int64_t expires_ns = 0;  ///< nanoseconds since the Unix epoch, on the database's clock
};

struct EstimateRecord {
  std::string vehicle;
  std::string model;
  std::string scope;         ///< what was fitted: a run id, or a pool's name
  std::int64_t time_ns = 0;  ///< nanoseconds since the Unix epoch
  std::string encoded;       ///< the encoded estimate table
};

class Store {
 public:
  /// Opens the location's backend (a file path or a postgresql:// URI: location.hpp), creating
  /// the file or schema if absent, checks it, brings its schema up to date and resets the
  /// folded marks to the checkpoints. StoreError/CorruptionError name the location.
  explicit Store(const std::string& location, StoreOptions options = {});
  ~Store();
  Store(Store&&) noexcept;
  Store& operator=(Store&&) noexcept;

  /// The location as given (a path or a URI).
  const std::string& path() const;

  /// Records a run (and its vehicle on first sight) after announcement.validate(). The same
  /// announcement again is `already_known`; a different one for the same vehicle/run is
  /// InputError.
  AddRunResult add_run(const ingest::RunAnnouncement& announcement);
  /// The announcement as stored.
  ingest::RunAnnouncement announcement(const RunKey& run);
  /// Validates against the run's announcement, then stores durably (see Ordering above).
  StoreChunkResult store_chunk(const ingest::Chunk& chunk);
  /// The same for a chunk validated on arrival: validate_chunk is not run again when the chunk
  /// was checked for this run's announcement under this store's limits (validated_for), and is
  /// otherwise.
  StoreChunkResult store_chunk(const ingest::ValidatedChunk& chunk);
  std::optional<std::uint64_t> highest_contiguous(const RunKey& run);
  std::optional<std::uint64_t> folded_through(const RunKey& run);
  /// Chunks from..to (inclusive) in order; `to` must not exceed highest_contiguous().
  ChunkStream chunks(const RunKey& run, std::uint64_t from, std::uint64_t to);
  /// The live accumulators have folded 0..sequence.
  void mark_folded(const RunKey& run, std::uint64_t sequence);
  /// The caller folds the vehicle's runs again from their newest checkpoints (a holder that
  /// has just taken the vehicle's lease): each run's folded mark goes back to its checkpoint.
  /// A write of the vehicle (fenced under a holder). An unknown vehicle: nothing to do.
  void restart_folds(const std::string& vehicle);
  /// Saves the state after folding 0..folded_through and raises the folded mark to it, in one
  /// transaction. folded_through must not exceed highest_contiguous() nor go below the latest
  /// checkpoint's; the same checkpoint again is a no-op, a different one at the same mark is
  /// InputError.
  void save_checkpoint(const RunKey& run, std::uint64_t folded_through, std::string_view state);
  std::optional<Checkpoint> latest_checkpoint(const RunKey& run);
  /// Appends to the vehicle's estimate history (the vehicle must be known).
  void record_estimate(const EstimateRecord& estimate);
  /// A vehicle's estimates of one model, oldest first.
  std::vector<EstimateRecord> estimate_history(const std::string& vehicle,
                                               const std::string& model);
  std::vector<std::string> list_vehicles();
  /// Runs of a known vehicle in announcement order.
  std::vector<RunInfo> list_runs(const std::string& vehicle);
  /// No new chunk is accepted afterwards (duplicates still re-acknowledge). Idempotent.
  void close_run(const RunKey& run);
  /// Takes the vehicle's lease for `holder` until now + ttl if it is free, expired or already
  /// holder's (then renewed); returns the lease as it stands afterwards: holder's if taken,
  /// else the other holder's. ttl must be positive (InputError).
  Lease acquire_lease(const std::string& vehicle, const std::string& holder,
                      std::chrono::milliseconds ttl);
  /// Ends holder's lease of the vehicle now; another holder's is left alone.
  void release_lease(const std::string& vehicle, const std::string& holder);
  /// Every lease, expired ones included, by vehicle.
  std::vector<Lease> leases();
  /// Runs f(*this) as one transaction (see Group commit above); InputError inside a batch.
  /// Meant for the chunk path's writes (store_chunk, mark_folded, save_checkpoint,
  /// record_estimate): close_run's and add_run's run cache is not rolled back with it.
  void batch(const std::function<void(Store&)>& f);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynid::store
