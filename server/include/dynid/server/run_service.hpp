#pragma once
// RunService: the runs of the vehicles pinned to one worker, and everything done to them:
// the chunk path (DESIGN.md, "Storage"), restart, throttled estimate publication, and the
// run-level requests. One per worker; only that worker's thread calls it, so it needs no lock
// of its own (the store is shared through SharedStore).
//
// Chunk path, with group commit, pipelined: receive_chunk validates the chunk against the
// run's announcement and queues it; at the end of the worker's batch of tasks (publish_due,
// the worker's tick) and every kMaxBatch chunks the queue goes to the Committer
// (committer.hpp), which stores it with the other worker's in one transaction (one fsync)
// while this worker goes on; once committed, the committer wakes the worker
// (collect_committed) and, in submission order:
//   -> publish one ChunkAck per run (highest contiguous stored, recent rejections with reasons)
//   -> fold every stored contiguous chunk not yet folded, in sequence order (a chunk stored
//      ahead of a gap is folded when the gap closes)
//   -> the folded marks, and a checkpoint every `checkpoint_every` folded chunks of a run (the
//      state taken right after that chunk, with its estimate history entry), are saved in the next
//      batch's transaction, or as a batch of their own when the worker is idle: one fsync per
//      batch
// Before any other call (an announcement, a request, a resume) flush_pending() waits for every
// batch, so it sees every chunk received before it.
//   -> the run's estimates are published at most every `publish_interval` (publish_due).
//      The Estimate instance is (vehicle, model), shared by the vehicle's runs and pools, and
//      readers keep its latest sample. So a vehicle's changed runs are published together, the
//      most recently changed last, and a pool after them: an older run's throttled table never
//      overtakes a newer run's, nor the pool an engineer just asked for.
// A chunk is acknowledged only once its batch has committed: never before it is durable. A
// rejected chunk (unknown run, invalid, conflicting, too far ahead, closed run) is counted,
// listed in the ack with its reason, and changes no state. A store failure acknowledges
// nothing of the batch (the cars resend).
//
// Restart (resume): the latest checkpoint is restored (a damaged one is reported and the run
// rebuilt from #0), the stored chunks after it are replayed, and the ledger's folded mark
// moves forward with them, so nothing is folded twice. Open runs are resumed at start; closed
// runs are loaded (and finished) the first time a request needs them. A stored chunk that
// cannot be read back (damaged: CorruptionError naming the file and the chunk) fails the load,
// and the run is not kept part way: every request on it fails the same way until the store is
// restored, rather than serving a partial run as if it were complete.
//
// Leases (several servers on one PostgreSQL store, lease_keeper.hpp): the store is fenced by
// this server's id, so a write of a vehicle whose lease was lost is refused (NotHolderError).
// Its chunks are then not acknowledged (the car resends them to the new holder), its marks and
// checkpoints not saved, and its runs dropped from memory (forget).
//
// Should a stored chunk be refused by the processor (a model rejects its rows), the run stops
// folding ("halted", with the reason, logged and in the ack); its chunks stay in the store for
// a reprocess.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "dynid/cancellation.hpp"
#include "dynid/dds/chunk_receipt.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "dynid/ingest/validated_chunk.hpp"
#include "dynid/ls/fleet.hpp"
#include "dynid/server/committer.hpp"
#include "dynid/server/counters.hpp"
#include "dynid/server/estimate_tables.hpp"
#include "dynid/server/options.hpp"
#include "dynid/server/residual_requests.hpp"
#include "dynid/server/shared_store.hpp"
#include "dynid/server/vehicle_outputs.hpp"

namespace dynid::server {

/// A request names something that does not exist (reply status NOT_FOUND).
class NotFound : public InputError {
 public:
  using InputError::InputError;
};

/// What all workers share.
struct ServerContext {
  const ServerOptions& options;
  SharedStore& store;
  Committer& committer;  // the store's writes of the chunk path
  ServerCounters& counters;
  const dds::Participant& participant;
  RevisionClock& revisions;
  /// Cancelled when the server stops: the live residual job's computation checks it.
  std::shared_ptr<const Cancellation> stopping;
};

/// A vehicle's part of a fleet request: its model's groups merged over the runs used.
struct FleetSource {
  std::optional<ls::FleetMember> member;  ///< always set by RunService::fleet_member
  std::vector<std::string> runs;
};

class RunService {
 public:
  explicit RunService(ServerContext& context) : context_(context) {}

  void announce(const ingest::RunAnnouncement& announcement);
  void receive_chunk(const std::shared_ptr<const ingest::Chunk>& chunk);
  /// A chunk sample that could not even be read (from_wire failed): reported to its sender
  /// when its vehicle and run ids are readable.
  void reject_unreadable(const std::string& vehicle, const std::string& run,
                         std::uint64_t sequence, const std::string& reason);
  void resume(const store::RunKey& key);
  /// The worker's tick: hands the queued chunks to the committer, acknowledges and folds the
  /// batches already committed, publishes the estimates of runs that changed and whose
  /// interval has passed; idle, hands the unsaved folded marks and checkpoints to the committer.
  void publish_due(std::chrono::steady_clock::time_point now);
  /// Acknowledges and folds the batches the committer has committed (what its wake-up runs).
  void collect_committed();
  /// Stores, acknowledges and folds the chunks receive_chunk queued and waits for every batch
  /// in flight (see above).
  void flush_pending();
  /// How the committer wakes this service's worker after a commit; it must not block (the
  /// server posts collect_committed() to the worker's queue). Set before the first chunk.
  void set_waker(std::function<void()> wake) { wake_ = std::move(wake); }
  /// flush_pending(), then saves the folded marks and checkpoints still unsaved: the store's
  /// ledger is then up to date (before a request reads it, and on every tick).
  void settle();
  /// Drops every run of `vehicle` from memory, after flush_pending() (its chunks received so far
  /// are stored or refused, and acknowledged if stored); with `save`, after publishing its
  /// estimates not published yet and saving its unsaved folded marks and checkpoints too. For a vehicle whose lease this server gives back (save)
  /// or lost (not: its writes fail), and before serving one whose lease it just took: the runs
  /// are then loaded from the store again (lease_keeper.hpp).
  void forget(const std::string& vehicle, bool save);
  /// Before serving a vehicle whose lease this server just took: forget(vehicle, false), and
  /// its runs' folded marks set back to their checkpoints, from where they are folded again
  /// (store.hpp, Folding). A lease lost meanwhile is reported as for a write (lease_lost).
  void take_over(const std::string& vehicle);
  /// How a write refused for a lost lease (store::NotHolderError) is reported: the vehicle's
  /// chunks of that batch are not acknowledged, its runs are dropped (forget), and `lost`
  /// (the server: LeaseKeeper::forget) is told. Set before the first chunk.
  void set_lease_lost(std::function<void(const std::string& vehicle)> lost) {
    lease_lost_ = std::move(lost);
  }

  // Run-level requests. InputError/NotFound name what is wrong.
  EstimateTables estimate(const std::string& vehicle, const std::optional<std::string>& run,
                          const std::optional<std::string>& model);
  /// What the run (latest by default) identifies and which manoeuvres would bring the rest
  /// (report/excitation_report.hpp).
  report::ExcitationReport excitation(const std::string& vehicle, const std::optional<std::string>& run);
  /// Also published on the Estimate topic (source "pool:<run>+<run>...").
  EstimateTables pooled(const std::string& vehicle, const std::vector<std::string>& runs,
                        const std::optional<std::string>& model);
  /// A vehicle's accumulators of `model` for a fleet estimate: its closed runs that run the
  /// model, merged; when none is closed, its latest run (open or not).
  FleetSource fleet_member(const std::string& vehicle, const std::string& model);
  EstimateTables close(const std::string& vehicle, const std::string& run);
  EstimateTables reprocess(const std::string& vehicle, const std::string& run,
                           const std::string& model, const std::vector<std::string>& effects);
  std::string base_report(const std::string& vehicle, const std::string& run,
                          const std::string& model, bool json);
  std::string list_runs(const std::string& vehicle, bool json);
  /// The residual loop on a stored run (residual_requests.hpp): the run replayed from the store.
  ResidualReply residual(const std::string& vehicle, const std::string& run,
                         const ResidualRequest& request);

 private:
  struct UnsavedCheckpoint {
    std::uint64_t through = 0;
    std::string state;
    EstimateTables tables;  // for the estimate history
  };
  struct RunState {
    explicit RunState(ingest::RunProcessor p) : processor(std::move(p)) {}
    ingest::RunProcessor processor;
    std::int64_t contiguous = -1;
    std::uint64_t since_checkpoint = 0;
    std::deque<dds::ChunkRejection> rejections;
    std::string halted;
    std::uint64_t changed = 0;  // when it last changed, on changes_ (orders publications)
    std::chrono::steady_clock::time_point last_published{};
    // Per model, the revision this run's table last went out with: a reply's tables carry it,
    // so that a reply and the topic name one table by one revision.
    std::map<std::string, std::uint64_t> published_revision;
    std::optional<std::uint64_t> unsaved_fold;  // folded through, not yet in the ledger
    std::vector<UnsavedCheckpoint> unsaved_checkpoints;
    // The live residual verdict (--live-residual): per model, and the chunks it includes.
    std::map<std::string, LiveVerdict> residual;
    std::int64_t residual_through = -1;
    // The first verdict waits an interval from the run's load (or its close): a few chunks carry
    // too little to measure a noise floor on.
    std::chrono::steady_clock::time_point residual_at = std::chrono::steady_clock::now();
    // The channel health of the stored chunks through `health_through` (run_health()).
    ingest::RunHealth health;
    std::int64_t health_through = -1;
  };
  struct PendingChunk {
    store::RunKey key;
    ingest::ValidatedChunk chunk;  // the dispatcher's decoded chunk, shared (no copy), checked
  };
  /// A run's marks and checkpoints taken out of it, for a transaction on any thread.
  struct SavedFold {
    store::RunKey key;
    std::vector<UnsavedCheckpoint> checkpoints;
    std::optional<std::uint64_t> mark;
  };
  /// A chunk's write refused because this server no longer holds its vehicle's lease.
  struct NotHolder {
    std::string reason;
  };
  /// A batch at the committer: written there, read by the worker only once `done`.
  struct InFlight {
    std::vector<PendingChunk> chunks;
    std::vector<SavedFold> folds;
    std::vector<std::variant<store::StoreChunkResult, std::string, NotHolder>> results;
    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    bool committed = false;
    std::string error;  // why not, when not committed
  };

  RunState* find(const store::RunKey& key);
  RunState& load(const store::RunKey& key);  // NotFound for an unknown run
  RunState& load_from_store(const store::RunKey& key);
  ingest::RunProcessor restore_processor(const store::RunKey& key,
                                         const ingest::RunAnnouncement& announcement);
  void reject(const store::RunKey& key, RunState* run, std::uint64_t sequence,
              const std::string& reason);
  void publish_ack(const store::RunKey& key, const RunState* run,
                   const std::vector<dds::ChunkRejection>& extra = {});
  void submit_pending();
  void submit(std::vector<PendingChunk>& chunks);
  /// Applies the committed batches in order; with `wait`, waits for every one in flight.
  void collect(bool wait);
  bool collect_one(bool wait);
  void apply(const InFlight& batch);
  void fold_ready(const store::RunKey& key, RunState& run,
                  const std::vector<const ingest::ValidatedChunk*>& in_hand);
  std::vector<ingest::Chunk> read_next(const store::RunKey& key, const RunState& run);
  bool fold_one(const store::RunKey& key, RunState& run, std::uint64_t sequence,
                const std::function<void()>& push);
  std::vector<ingest::Chunk> read_chunks(const store::RunKey& key, std::uint64_t from,
                                         std::uint64_t to);
  /// Every stored chunk of the run up to the highest contiguous one, in order, to `sink`.
  void replay_stored(const store::RunKey& key, const RunState& run,
                     const std::function<void(const ingest::Chunk&)>& sink);
  /// The channel health of the run's stored chunks (ingest/channel_health.hpp), computed again
  /// only when chunks joined since: a reply's tables then say which models cannot be judged.
  const ingest::RunHealth& run_health(const store::RunKey& key, RunState& run);
  void take_checkpoint(const store::RunKey& key, RunState& run);
  void save_folds(const std::vector<store::RunKey>& keys);
  std::vector<SavedFold> take_unsaved(const std::vector<store::RunKey>& keys);
  static void write_folds(store::Store& s, const std::vector<SavedFold>& folds,
                          ServerCounters& counters);
  void publish(const store::RunKey& key, RunState& run);
  /// With the live verdict on, a run that has grown since its verdict is due a new one
  /// (residual_requests.hpp: live_verdicts()), started once the interval has passed or the run
  /// is finished and no other diagnosis of this worker is in flight. With it off, a finished run
  /// is due the publication's IV and SIMEX fits alone, once: the tables publish what the
  /// publication rule chooses (residual/publication.hpp) whether or not the live verdict runs.
  void refresh_residual(const store::RunKey& key, const RunState& run);
  void start_residual_job();
  /// A finished diagnosis into its run, which is then published again.
  void collect_residual_job();
  /// The run's live judgement into its tables (nothing when off or not computed): the residual
  /// verdict, and the values the publication rule chooses from the IV and SIMEX fits
  /// (apply_publication, residual/publication.hpp; `estimates`: those the tables were made from).
  static void attach_live(const RunState& run, const std::vector<ingest::ModelEstimate>& estimates,
                          EstimateTables& tables);
  /// Writes `tables` to the Estimate topic, each with the next revision (set in `tables`).
  void publish_tables(const std::string& vehicle, EstimateTables& tables);
  /// Each table's revision as this run last published it (0: never published).
  static void stamp_revisions(const RunState& run, EstimateTables& tables);
  /// Publishes now every run of `vehicle` whose estimates changed since their last publication,
  /// in the order they changed.
  void publish_pending(const std::string& vehicle);
  /// The run's estimates changed since their last publication (dirty_).
  void mark_changed(const store::RunKey& key, RunState& run);
  void record_history(const store::RunKey& key, const EstimateTables& tables);
  static void record_history(store::Store& s, const store::RunKey& key,
                             const EstimateTables& tables);
  std::string latest_run(const std::string& vehicle);

  ServerContext& context_;
  std::map<store::RunKey, std::unique_ptr<RunState>> runs_;
  std::vector<PendingChunk> pending_;  // received, validated, not yet at the committer
  std::deque<std::shared_ptr<InFlight>> in_flight_;  // at the committer, oldest first
  std::function<void()> wake_;
  std::function<void(const std::string&)> lease_lost_;
  /// The vehicle's lease is lost (a write said NotHolderError): forget it, tell lease_lost_.
  void lost_lease(const std::string& vehicle, const std::string& reason);
  /// forget() without the flush.
  void drop(const std::string& vehicle, bool save);
  std::uint64_t changes_ = 0;          // RunState::changed counter
  std::set<store::RunKey> dirty_;      // runs whose estimates changed since their publication
  // The live residual verdict (--live-residual): runs whose verdict is older than their chunks,
  // and the one diagnosis in flight. One job per worker at a time, on a thread of its own: the
  // diagnoses take one core beside the folding and never hold an acknowledgement back.
  struct ResidualJob {
    store::RunKey key;
    std::int64_t through = -1;
    std::future<std::map<std::string, LiveVerdict>> verdicts;
  };
  std::set<store::RunKey> residual_stale_;
  std::optional<ResidualJob> residual_job_;
  std::vector<store::RunKey> unsaved_;  // runs whose folded mark or checkpoint is not saved
  VehicleOutputs outputs_;
};

}  // namespace dynid::server
