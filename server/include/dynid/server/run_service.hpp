#pragma once
// RunService: the runs of the vehicles pinned to one worker, and everything done to them:
// the chunk path (DESIGN.md, "Storage"), restart, throttled estimate publication, and the
// run-level requests. One per worker; only that worker's thread calls it, so it needs no lock
// of its own (the store is shared through SharedStore).
//
// Chunk path, with group commit: receive_chunk validates the chunk against the run's
// announcement and queues it; flush_pending(), at the end of the worker's batch of tasks
// (publish_due, the worker's tick), before any other call (so a request or announcement sees
// every chunk received before it), and every kMaxBatch chunks, then:
//   store the queued chunks in one transaction (Store::batch: durable with one fsync)
//   -> publish one ChunkAck per run (highest contiguous stored, recent rejections with reasons)
//   -> fold every stored contiguous chunk not yet folded, in sequence order (a chunk stored
//      ahead of a gap is folded when the gap closes)
//   -> the folded marks, and a checkpoint every `checkpoint_every` folded chunks of a run (the
//      state taken right after that chunk, with its estimate history entry), are saved in the next
//      batch's transaction, or on the next tick when no chunk came: one fsync per batch
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
// Should a stored chunk be refused by the processor (a model rejects its rows), the run stops
// folding ("halted", with the reason, logged and in the ack); its chunks stay in the store for
// a reprocess.
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "dynid/dds/chunk_receipt.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "dynid/ls/fleet.hpp"
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
  ServerCounters& counters;
  const dds::Participant& participant;
  RevisionClock& revisions;
};

/// A vehicle's part of a fleet request: its model's groups merged over the runs used.
struct FleetSource {
  std::optional<ls::FleetMember> member;  ///< always set by RunService::fleet_member
  std::vector<std::string> runs;
};

/// The sequence a rejection of the announcement itself carries in a ChunkAck.
inline constexpr std::uint64_t kAnnouncementSequence = ~std::uint64_t{0};

class RunService {
 public:
  explicit RunService(ServerContext& context) : context_(context) {}

  void announce(const ingest::RunAnnouncement& announcement);
  void receive_chunk(const ingest::Chunk& chunk);
  /// A chunk sample that could not even be read (from_wire failed): reported to its sender
  /// when its vehicle and run ids are readable.
  void reject_unreadable(const std::string& vehicle, const std::string& run,
                         std::uint64_t sequence, const std::string& reason);
  void resume(const store::RunKey& key);
  /// The worker's tick: stores, acknowledges and folds the queued chunks (flush_pending); when
  /// there were none (idle), saves the folded marks and checkpoints still unsaved; then
  /// publishes the estimates of runs that changed and whose interval has passed.
  void publish_due(std::chrono::steady_clock::time_point now);
  /// Stores, acknowledges and folds the chunks receive_chunk queued (see above).
  void flush_pending();
  /// flush_pending(), then saves the folded marks and checkpoints still unsaved: the store's
  /// ledger is then up to date (before a request reads it, and on every tick).
  void settle();

  // Run-level requests. InputError/NotFound name what is wrong.
  EstimateTables estimate(const std::string& vehicle, const std::optional<std::string>& run,
                          const std::optional<std::string>& model);
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
    std::optional<std::uint64_t> unsaved_fold;  // folded through, not yet in the ledger
    std::vector<UnsavedCheckpoint> unsaved_checkpoints;
  };
  struct PendingChunk {
    store::RunKey key;
    ingest::Chunk chunk;
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
  std::vector<std::variant<store::StoreChunkResult, std::string>> store_batch(
      const std::vector<PendingChunk>& batch);
  void fold_ready(const store::RunKey& key, RunState& run,
                  const std::vector<const ingest::Chunk*>& in_hand);
  std::vector<ingest::Chunk> next_chunks(const store::RunKey& key, const RunState& run,
                                         const std::vector<const ingest::Chunk*>& in_hand);
  std::vector<ingest::Chunk> read_chunks(const store::RunKey& key, std::uint64_t from,
                                         std::uint64_t to);
  /// Every stored chunk of the run up to the highest contiguous one, in order, to `sink`.
  void replay_stored(const store::RunKey& key, const RunState& run,
                     const std::function<void(const ingest::Chunk&)>& sink);
  void take_checkpoint(const store::RunKey& key, RunState& run);
  void save_folds(const std::vector<store::RunKey>& keys);
  void save_fold(store::Store& s, const store::RunKey& key, RunState& run);
  void save_unsaved(store::Store& s);
  void publish(const store::RunKey& key, RunState& run);
  void publish_tables(const std::string& vehicle, EstimateTables tables);
  /// Publishes now every run of `vehicle` whose estimates changed since their last publication,
  /// in the order they changed.
  void publish_pending(const std::string& vehicle);
  /// The run's estimates changed since their last publication (dirty_).
  void mark_changed(const store::RunKey& key, RunState& run);
  void record_history(const store::RunKey& key, const EstimateTables& tables);
  void record_history(store::Store& s, const store::RunKey& key, const EstimateTables& tables);
  std::string latest_run(const std::string& vehicle);

  ServerContext& context_;
  std::map<store::RunKey, std::unique_ptr<RunState>> runs_;
  std::vector<PendingChunk> pending_;  // received, validated, not yet stored
  std::uint64_t changes_ = 0;          // RunState::changed counter
  std::set<store::RunKey> dirty_;      // runs whose estimates changed since their publication
  std::vector<store::RunKey> unsaved_;  // runs whose folded mark or checkpoint is not saved
  VehicleOutputs outputs_;
};

}  // namespace dynid::server
