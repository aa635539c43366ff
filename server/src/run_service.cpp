// RunService: the chunk path, restart and publication (contract in run_service.hpp).
#include "dynid/server/run_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include <dynid/input/ids.hpp>

#include "dynid/dds/conversions.hpp"
#include "dynid/dds/protocol.hpp"
#include "dynid/report/estimate_report.hpp"

namespace dynid::server {

namespace {

using dds::protocol::kAnnouncementSequence;
constexpr std::uint64_t kReplayBatch = 16;      // chunks read from the store per lock
constexpr std::size_t kMaxBatch = 256;          // chunks stored per transaction at most
constexpr std::size_t kMaxInFlight = 2;         // batches a worker has at the committer at most

// Escaped: ids come from the network, and a log line must not be forged by one.
std::string label(const store::RunKey& key) {
  return input::printable(key.vehicle) + "/" + input::printable(key.run);
}

std::int64_t as_mark(const std::optional<std::uint64_t>& sequence) {
  return sequence ? static_cast<std::int64_t>(*sequence) : -1;
}

}  // namespace

// ---- runs in memory ------------------------------------------------------------------

RunService::RunState* RunService::find(const store::RunKey& key) {
  const auto it = runs_.find(key);
  return it == runs_.end() ? nullptr : it->second.get();
}

RunService::RunState& RunService::load(const store::RunKey& key) {
  if (RunState* run = find(key)) return *run;
  const bool known = context_.store.with([&](store::Store& s) {
    const auto vehicles = s.list_vehicles();
    if (std::find(vehicles.begin(), vehicles.end(), key.vehicle) == vehicles.end()) return false;
    for (const auto& info : s.list_runs(key.vehicle))
      if (info.run == key.run) return true;
    return false;
  });
  if (!known) throw NotFound("run " + label(key) + ": unknown run (never announced)");
  return load_from_store(key);
}

ingest::RunProcessor RunService::restore_processor(const store::RunKey& key,
                                                   const ingest::RunAnnouncement& announcement) {
  try {
    const auto checkpoint =
        context_.store.with([&](store::Store& s) { return s.latest_checkpoint(key); });
    if (checkpoint)
      return ingest::RunProcessor::restore(announcement, checkpoint->state,
                                           context_.options.store.limits);
  } catch (const std::exception& e) {  // damaged: the chunks are the truth, replay from #0
    spdlog::error("run {}: checkpoint unusable, replaying from #0: {}", label(key), e.what());
  }
  return ingest::RunProcessor(announcement, context_.options.store.limits);
}

RunService::RunState& RunService::load_from_store(const store::RunKey& key) {
  const auto [announcement, closed, contiguous] = context_.store.with([&](store::Store& s) {
    bool is_closed = false;
    for (const auto& info : s.list_runs(key.vehicle))
      if (info.run == key.run) is_closed = info.closed;
    return std::make_tuple(s.announcement(key), is_closed, as_mark(s.highest_contiguous(key)));
  });
  auto state = std::make_unique<RunState>(restore_processor(key, announcement));
  state->contiguous = contiguous;
  RunState& run = *runs_.emplace(key, std::move(state)).first->second;
  const std::uint64_t from = run.processor.next_sequence();
  try {
    fold_ready(key, run, {});
  } catch (...) {  // e.g. a damaged chunk: a run folded part way must never be served
    runs_.erase(key);
    throw;
  }
  save_folds({key});
  if (closed && !run.processor.finished()) run.processor.finish();
  spdlog::info("run {}: resumed at #{} ({} stored contiguously{})", label(key), from,
               run.contiguous + 1, closed ? ", closed" : "");
  mark_changed(key, run);
  return run;
}

void RunService::resume(const store::RunKey& key) {
  flush_pending();
  try {
    load(key);
  } catch (const std::exception& e) {
    spdlog::error("run {}: cannot resume: {}", label(key), e.what());
  }
}

// ---- announcements -----------------------------------------------------------------

void RunService::announce(const ingest::RunAnnouncement& announcement) {
  flush_pending();
  const store::RunKey key{announcement.vehicle, announcement.run};
  try {
    // The processor validates the models too (unknown model, bad constant, wrong unit), so a
    // run that could never be processed is refused before anything is stored.
    ingest::RunProcessor processor(announcement, context_.options.store.limits);
    const auto added = context_.store.with([&](store::Store& s) { return s.add_run(announcement); });
    context_.counters.add(&CounterSnapshot::announcements);
    if (find(key)) return;  // announced again (transient-local, a car restart): nothing new
    if (added == store::AddRunResult::already_known) {
      load_from_store(key);
    } else {
      runs_.emplace(key, std::make_unique<RunState>(std::move(processor)));
      spdlog::info("run {}: announced ({} channels at {} Hz, {} models)", label(key),
                   announcement.channels.size(), announcement.sample_rate_hz,
                   announcement.models.size());
    }
    publish_ack(key, find(key));
  } catch (const InputError& e) {
    context_.counters.add(&CounterSnapshot::rejected_announcements);
    spdlog::warn("announcement {} rejected: {}", label(key), e.what());
    publish_ack(key, find(key), {{kAnnouncementSequence, std::string("announcement rejected: ") + e.what()}});
  } catch (const store::NotHolderError& e) {  // the new holder answers it
    lost_lease(key.vehicle, e.what());
  }
}

// ---- chunks ----------------------------------------------------------------------------

void RunService::reject(const store::RunKey& key, RunState* run, std::uint64_t sequence,
                        const std::string& reason) {
  context_.counters.add(&CounterSnapshot::chunks_rejected);
  spdlog::warn("chunk {}#{} rejected: {}", label(key), sequence, reason);
  if (!run) {  // unknown run: nothing is kept for it, the ack carries this one reason
    publish_ack(key, nullptr, {{sequence, reason}});
    return;
  }
  run->rejections.push_back({sequence, reason});
  if (run->rejections.size() > dds::protocol::kMaxRejections) run->rejections.pop_front();
  publish_ack(key, run);
}

void RunService::reject_unreadable(const std::string& vehicle, const std::string& run,
                                   std::uint64_t sequence, const std::string& reason) {
  flush_pending();
  const store::RunKey key{vehicle, run};
  reject(key, find(key), sequence, reason);
}

void RunService::receive_chunk(const std::shared_ptr<const ingest::Chunk>& chunk) {
  const store::RunKey key{chunk->vehicle, chunk->run};
  RunState* run = find(key);
  if (!run) {
    try {
      run = &load(key);  // a run announced before a restart, or never announced
    } catch (const NotFound&) {
      return reject(key, nullptr, chunk->sequence, "unknown run " + label(key) + " (never announced)");
    }
  }
  try {  // once: the store and the processor take the ValidatedChunk as checked
    pending_.push_back({key, ingest::ValidatedChunk::validate(chunk, run->processor.announcement(),
                                                              context_.options.store.limits)});
  } catch (const InputError& e) {
    return reject(key, run, chunk->sequence, e.what());
  }
  if (pending_.size() >= kMaxBatch) submit_pending();
}

void RunService::flush_pending() {
  submit_pending();
  collect(true);
}

// Hands the queued chunks, with the folded marks and checkpoints not yet saved (they ride
// along: one fsync for all), to the committer; the worker folds on meanwhile.
void RunService::submit_pending() {
  if (!pending_.empty()) submit(pending_);
}

// `chunks` (moved out) and the unsaved marks and checkpoints as one batch to the committer.
void RunService::submit(std::vector<PendingChunk>& chunks) {
  while (in_flight_.size() >= kMaxInFlight) collect_one(true);  // bounds the memory held
  auto batch = std::make_shared<InFlight>();
  batch->chunks.swap(chunks);
  batch->folds = take_unsaved(std::exchange(unsaved_, {}));
  batch->results.resize(batch->chunks.size());
  in_flight_.push_back(batch);
  context_.committer.submit(
      [batch, &counters = context_.counters](store::Store& s) {
        write_folds(s, batch->folds, counters);
        for (std::size_t i = 0; i < batch->chunks.size(); ++i) {
          try {
            batch->results[i] = s.store_chunk(batch->chunks[i].chunk);
          } catch (const InputError& e) {  // rolled back alone; the others stay
            batch->results[i] = std::string(e.what());
          } catch (const store::NotHolderError& e) {  // nothing written: the others stay
            batch->results[i] = NotHolder{e.what()};
          }
        }
      },
      [batch, wake = wake_](bool committed, const std::string& error) {
        {
          std::lock_guard lock(batch->mutex);
          batch->done = true;
          batch->committed = committed;
          batch->error = error;
        }
        batch->finished.notify_all();
        if (wake) wake();
      });
}

void RunService::collect_committed() { collect(false); }

void RunService::collect(bool wait) {
  while (!in_flight_.empty() && collect_one(wait)) {
  }
}

// The oldest batch in flight, once committed: acknowledged and folded. False when it is not
// done yet and `wait` is false.
bool RunService::collect_one(bool wait) {
  const std::shared_ptr<InFlight> batch = in_flight_.front();
  {
    std::unique_lock lock(batch->mutex);
    if (!wait && !batch->done) return false;
    batch->finished.wait(lock, [&] { return batch->done; });
  }
  in_flight_.pop_front();
  if (!batch->committed) {  // not stored: nothing acknowledged, the cars resend
    if (batch->chunks.empty()) {
      spdlog::error("folded marks and checkpoints of {} runs not saved: {}", batch->folds.size(),
                    batch->error);
      return true;
    }
    context_.counters.add(&CounterSnapshot::store_errors, batch->chunks.size());
    spdlog::error("{} chunks not stored ({}#{}..): {}", batch->chunks.size(),
                  label(batch->chunks.front().key), batch->chunks.front().chunk.chunk().sequence,
                  batch->error);
    return true;
  }
  apply(*batch);
  return true;
}

// A committed batch: every chunk's outcome into its run, one ack per run, then the folds.
void RunService::apply(const InFlight& batch) {
  std::vector<store::RunKey> touched;  // runs with news, in arrival order
  std::map<store::RunKey, std::vector<const ingest::ValidatedChunk*>> stored;
  std::map<std::string, std::string> lost;  // vehicle -> why: its lease is gone
  for (std::size_t i = 0; i < batch.chunks.size(); ++i) {
    const store::RunKey& key = batch.chunks[i].key;
    const ingest::Chunk& chunk = batch.chunks[i].chunk.chunk();
    if (const auto* refused = std::get_if<NotHolder>(&batch.results[i])) {
      lost.emplace(key.vehicle, refused->reason);
      continue;
    }
    if (lost.contains(key.vehicle)) continue;
    RunState* run = find(key);  // loaded by receive_chunk; only its own failed load unloads it
    if (!run) continue;         // stored all the same: a later load replays it
    if (const auto* refused = std::get_if<std::string>(&batch.results[i])) {
      reject(key, run, chunk.sequence, *refused);
      continue;
    }
    const auto& result = std::get<store::StoreChunkResult>(batch.results[i]);
    run->contiguous = as_mark(result.contiguous_through);
    if (result.status == store::ChunkStatus::conflict ||
        result.status == store::ChunkStatus::beyond_window) {
      reject(key, run, chunk.sequence, result.reason);
      continue;
    }
    const bool is_new = result.status == store::ChunkStatus::stored;
    context_.counters.add(is_new ? &CounterSnapshot::chunks_stored : &CounterSnapshot::chunks_duplicate);
    if (is_new) stored[key].push_back(&batch.chunks[i].chunk);
    if (std::find(touched.begin(), touched.end(), key) == touched.end()) touched.push_back(key);
  }
  // Not one chunk of a vehicle whose lease is gone is acknowledged, even one stored before the
  // refusal in this batch: the new holder acknowledges it when the car resends it.
  std::erase_if(touched, [&](const store::RunKey& key) { return lost.contains(key.vehicle); });
  // Durable now (the batch committed): acknowledge each run once, with its highest mark.
  for (const auto& key : touched) publish_ack(key, find(key));
  for (const auto& key : touched) fold_ready(key, *find(key), stored[key]);
  // Their folded marks and checkpoints ride with the next batch's transaction (or the next
  // idle tick's): one fsync per batch, not two.
  for (const auto& key : touched)
    if (std::find(unsaved_.begin(), unsaved_.end(), key) == unsaved_.end()) unsaved_.push_back(key);
  for (const auto& [vehicle, reason] : lost) lost_lease(vehicle, reason);
}

std::vector<ingest::Chunk> RunService::read_chunks(const store::RunKey& key, std::uint64_t from,
                                                   std::uint64_t to) {
  return context_.store.with([&](store::Store& s) {
    std::vector<ingest::Chunk> chunks;
    auto stream = s.chunks(key, from, to);
    while (auto chunk = stream.next()) chunks.push_back(std::move(*chunk));
    return chunks;
  });
}

// The next chunks to fold, read from the store (replay after a restart, chunks that were stored
// ahead of a gap): the next one and up to kReplayBatch - 1 after it.
std::vector<ingest::Chunk> RunService::read_next(const store::RunKey& key, const RunState& run) {
  const std::uint64_t next = run.processor.next_sequence();
  auto chunks = read_chunks(key, next, std::min<std::uint64_t>(next + kReplayBatch - 1, static_cast<std::uint64_t>(run.contiguous)));
  context_.counters.add(&CounterSnapshot::chunks_replayed, chunks.size());
  return chunks;
}

// Folds next_sequence()..contiguous in order, from the chunks in hand (validated on arrival:
// not validated again, not copied) when there, else from the store; the folded mark and a due
// checkpoint are kept in the run for save_folds().
void RunService::fold_ready(const store::RunKey& key, RunState& run,
                            const std::vector<const ingest::ValidatedChunk*>& in_hand) {
  if (!run.halted.empty() || run.processor.finished()) return;
  const std::uint64_t first = run.processor.next_sequence();
  while (run.halted.empty() && run.contiguous >= 0 &&
         run.processor.next_sequence() <= static_cast<std::uint64_t>(run.contiguous)) {
    const std::uint64_t next = run.processor.next_sequence();
    const auto hand = std::find_if(in_hand.begin(), in_hand.end(),
                                   [&](const auto* c) { return c->chunk().sequence == next; });
    if (hand != in_hand.end()) {
      fold_one(key, run, next, [&] { run.processor.push(**hand); });
      continue;
    }
    const auto chunks = read_next(key, run);
    if (chunks.empty()) break;  // the store returned nothing it counts as stored: never spin
    for (const auto& chunk : chunks)
      if (!fold_one(key, run, chunk.sequence, [&] { run.processor.push(chunk); })) break;
  }
  const std::uint64_t after = run.processor.next_sequence();
  if (after > first) run.unsaved_fold = after - 1;
}

// One chunk into the run's processor (push); false when the processor refused it: the run is
// then halted with the reason.
bool RunService::fold_one(const store::RunKey& key, RunState& run, std::uint64_t sequence,
                          const std::function<void()>& push) {
  try {
    push();
  } catch (const InputError& e) {
    run.halted = std::string("folding halted: ") + e.what();
    spdlog::error("run {}: {}", label(key), run.halted);
    run.rejections.push_back({sequence, run.halted});
    return false;
  }
  context_.counters.add(&CounterSnapshot::chunks_folded);
  mark_changed(key, run);
  if (++run.since_checkpoint >= context_.options.checkpoint_every) take_checkpoint(key, run);
  return true;
}

// The state right after this chunk, saved with the folded mark (every one of them: each is an
// entry of the estimate history).
void RunService::take_checkpoint(const store::RunKey& key, RunState& run) {
  run.since_checkpoint = 0;
  try {
    run.unsaved_checkpoints.push_back({run.processor.next_sequence() - 1, run.processor.checkpoint(),
                                       tables_of(key.vehicle, key.run, run.processor.estimates())});
  } catch (const std::exception& e) {
    spdlog::error("run {}: no checkpoint: {}", label(key), e.what());
  }
}

// The runs' folded marks and due checkpoints, in one transaction. A checkpoint only shortens
// a later replay: when it cannot be saved (a full disk, or a mark below a damaged newer
// checkpoint after a rebuild from #0), the run goes on without it. A folded mark that is not
// saved is harmless too: opening the store resets the marks to the checkpoints.
void RunService::save_folds(const std::vector<store::RunKey>& keys) {
  const auto folds = take_unsaved(keys);
  try {
    context_.store.with([&](store::Store& s) {
      s.batch([&](store::Store& b) { write_folds(b, folds, context_.counters); });
    });
  } catch (const std::exception& e) {
    spdlog::error("folded marks and checkpoints of {} runs not saved: {}", keys.size(), e.what());
  }
}

// What the runs have not saved yet, taken out of them (to be written by whichever
// transaction takes them; should it not commit, they are lost, which only lengthens a replay).
std::vector<RunService::SavedFold> RunService::take_unsaved(const std::vector<store::RunKey>& keys) {
  std::vector<SavedFold> folds;
  for (const auto& key : keys)
    if (RunState* run = find(key))
      folds.push_back({key, std::exchange(run->unsaved_checkpoints, {}),
                       std::exchange(run->unsaved_fold, std::nullopt)});
  return folds;
}

// Inside a transaction, on whichever thread runs it: touches no run, only the store.
void RunService::write_folds(store::Store& s, const std::vector<SavedFold>& folds,
                             ServerCounters& counters) {
  for (const auto& fold : folds) {
    for (const auto& checkpoint : fold.checkpoints) {
      try {
        s.save_checkpoint(fold.key, checkpoint.through, checkpoint.state);
        counters.add(&CounterSnapshot::checkpoints);
        record_history(s, fold.key, checkpoint.tables);
      } catch (const InputError& e) {
        spdlog::error("run {}: checkpoint through #{} not saved: {}", label(fold.key),
                      checkpoint.through, e.what());
      } catch (const store::NotHolderError& e) {  // the new holder replays from its own
        spdlog::warn("run {}: checkpoint through #{} not saved: {}", label(fold.key),
                     checkpoint.through, e.what());
      }
    }
    if (!fold.mark) continue;
    try {
      s.mark_folded(fold.key, *fold.mark);
    } catch (const InputError& e) {
      spdlog::error("run {}: folded mark #{} not saved: {}", label(fold.key), *fold.mark, e.what());
    } catch (const store::NotHolderError& e) {
      spdlog::warn("run {}: folded mark #{} not saved: {}", label(fold.key), *fold.mark, e.what());
    }
  }
}

// ---- publication -------------------------------------------------------------------------

void RunService::publish_ack(const store::RunKey& key, const RunState* run,
                             const std::vector<dds::ChunkRejection>& extra) {
  dds::ChunkReceipt receipt{key.vehicle, key.run, run ? run->contiguous : -1, {}};
  if (run) receipt.rejections.assign(run->rejections.begin(), run->rejections.end());
  receipt.rejections.insert(receipt.rejections.end(), extra.begin(), extra.end());
  try {
    auto& writers = outputs_.writers(context_.participant, key.vehicle);
    writers.ack.write(to_wire(receipt).data);
  } catch (const std::exception& e) {  // an id no partition can carry: the log is all we have
    spdlog::warn("no acknowledgement for {}: {}", label(key), e.what());
  }
}

void RunService::publish(const store::RunKey& key, RunState& run) {
  dirty_.erase(key);
  run.last_published = std::chrono::steady_clock::now();
  refresh_residual(key, run);
  const auto estimates = run.processor.estimates();
  EstimateTables tables = tables_of(key.vehicle, key.run, estimates);
  attach_live(run, estimates, tables);
  publish_tables(key.vehicle, tables);
  for (const dds::EstimateTable& table : tables.tables) run.published_revision[table.model] = table.revision;
}

void RunService::stamp_revisions(const RunState& run, EstimateTables& tables) {
  for (dds::EstimateTable& table : tables.tables) {
    const auto it = run.published_revision.find(table.model);
    table.revision = it == run.published_revision.end() ? 0 : it->second;
  }
}

void RunService::refresh_residual(const store::RunKey& key, const RunState& run) {
  if (run.contiguous < 0 || run.contiguous == run.residual_through) return;
  // Without the live verdict, a closed run still gets the publication's IV and SIMEX fits, once.
  if (context_.options.live_residual_interval.count() == 0 && !run.processor.finished()) return;
  residual_stale_.insert(key);
  start_residual_job();
}

void RunService::start_residual_job() {
  if (residual_job_) return;
  // Called from a tick or from a request's publication: the live job is the server's, not that
  // request's, so only the server's stop cancels reading its run back.
  const CancellationScope stop_only(context_.stopping);
  const auto now = std::chrono::steady_clock::now();
  for (auto it = residual_stale_.begin(); it != residual_stale_.end();) {
    RunState* run = find(*it);
    if (run == nullptr || run->contiguous == run->residual_through) {
      it = residual_stale_.erase(it);
      continue;
    }
    if (!run->processor.finished() && run->residual_through >= 0 &&
        now - run->residual_at < context_.options.live_residual_interval) {
      ++it;
      continue;
    }
    // Only the models this run excites: the loop's judgement of a model the run carries no
    // information about says nothing (and costs the most: every candidate is "significant").
    std::vector<std::string> models;
    std::vector<ingest::Chunk> chunks;
    run->residual_at = now;
    try {
      for (const dds::EstimateTable& t : tables_of(it->vehicle, it->run, run->processor.estimates()).tables)
        if (t.not_excited.empty()) models.push_back(t.model);
      // Read here: the store is this worker's to read.
      replay_stored(*it, *run, [&](const ingest::Chunk& chunk) { chunks.push_back(chunk); });
      const bool diagnose = context_.options.live_residual_interval.count() != 0;
      residual_job_.emplace(ResidualJob{
          *it, run->contiguous,
          std::async(std::launch::async, [announcement = run->processor.announcement(),
                                          chunks = std::move(chunks), models = std::move(models),
                                          stopping = context_.stopping, diagnose] {
            const CancellationScope scope(stopping);  // a stop does not wait for the verdict
            return live_verdicts(announcement, chunks, models, diagnose);
          })});
    } catch (const std::exception& e) {
      // A stored chunk that cannot be read back, or no thread to be had: no verdict, and the
      // worker's tick (or the publication that called it) goes on; tried again when the run is
      // published again.
      spdlog::warn("run {}: no live residual verdict: {}", label(*it), e.what());
      it = residual_stale_.erase(it);
      continue;
    }
    residual_stale_.erase(it);
    return;
  }
}

void RunService::collect_residual_job() {
  if (!residual_job_ || residual_job_->verdicts.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  ResidualJob job = std::move(*residual_job_);
  residual_job_.reset();
  std::map<std::string, LiveVerdict> verdicts;
  try {
    verdicts = job.verdicts.get();
  } catch (const std::exception& e) {  // a run that cannot be assembled yet: no verdict
    spdlog::debug("run {}: no live residual verdict: {}", label(job.key), e.what());
  }
  if (RunState* run = find(job.key)) {
    run->residual = std::move(verdicts);
    run->residual_through = job.through;
    spdlog::debug("run {}: live residual verdict through #{}", label(job.key), job.through);
    mark_changed(job.key, *run);  // published with the next tick
    if (run->contiguous != run->residual_through) residual_stale_.insert(job.key);
  }
  start_residual_job();
}

void RunService::attach_live(const RunState& run, const std::vector<ingest::ModelEstimate>& estimates,
                             EstimateTables& tables) {
  for (dds::EstimateTable& table : tables.tables) {
    const auto it = run.residual.find(table.model);
    if (it == run.residual.end()) continue;
    const LiveVerdict& live = it->second;
    const auto through = static_cast<std::uint64_t>(run.residual_through);
    if (!live.verdict.empty()) {
      table.residual_verdict = live.verdict;
      table.residual_statement = live.statement;
      table.residual_through = through;
    }
    const auto estimate = std::find_if(estimates.begin(), estimates.end(),
                                       [&](const ingest::ModelEstimate& e) { return e.model == table.model; });
    if (estimate == estimates.end() || !estimate->estimate) continue;
    apply_publication(table, estimate->parameters, *estimate->estimate,
                      live.iv ? &*live.iv : nullptr, live.simex ? &*live.simex : nullptr, through);
  }
}

void RunService::publish_tables(const std::string& vehicle, EstimateTables& tables) {
  auto& writers = outputs_.writers(context_.participant, vehicle);
  for (auto& table : tables.tables) {
    table.revision = context_.revisions.next();
    writers.estimate.write(to_wire(table).data);
    context_.counters.add(&CounterSnapshot::estimates_published);
  }
}

void RunService::mark_changed(const store::RunKey& key, RunState& run) {
  run.changed = ++changes_;
  dirty_.insert(key);
}

void RunService::publish_pending(const std::string& vehicle) {
  std::vector<std::pair<store::RunKey, RunState*>> changed;
  // dirty_ is ordered by vehicle: its changed runs are adjacent, from the first with its name.
  for (auto it = dirty_.lower_bound({vehicle, {}}); it != dirty_.end() && it->vehicle == vehicle; ++it)
    if (RunState* run = find(*it)) changed.emplace_back(*it, run);
  std::sort(changed.begin(), changed.end(),
            [](const auto& a, const auto& b) { return a.second->changed < b.second->changed; });
  for (const auto& [key, run] : changed) {
    try {
      publish(key, *run);
    } catch (const std::exception& e) {
      spdlog::error("run {}: estimates not published: {}", label(key), e.what());
    }
  }
}

void RunService::forget(const std::string& vehicle, bool save) {
  flush_pending();
  // Given back: what it folded since its last publication goes out now; no other server
  // publishes the vehicle's estimates before its next chunk.
  if (save) publish_pending(vehicle);
  drop(vehicle, save);
}

void RunService::take_over(const std::string& vehicle) {
  forget(vehicle, false);
  try {
    context_.store.with([&](store::Store& s) { s.restart_folds(vehicle); });
  } catch (const store::NotHolderError& e) {
    lost_lease(vehicle, e.what());
  } catch (const std::exception& e) {  // the marks only lag: the folds restart from checkpoints
    spdlog::error("vehicle {}: folded marks not set back: {}", input::printable(vehicle), e.what());
  }
}

// Without flushing: also called while a committed batch is applied (lost_lease), where the
// batches behind it must still be applied in order by the collect() under way.
void RunService::drop(const std::string& vehicle, bool save) {
  std::vector<store::RunKey> keys;
  for (const auto& [key, run] : runs_)
    if (key.vehicle == vehicle) keys.push_back(key);
  const auto unsaved = std::stable_partition(unsaved_.begin(), unsaved_.end(),
                                      [&](const store::RunKey& key) { return key.vehicle != vehicle; });
  if (save && unsaved != unsaved_.end()) save_folds(std::vector<store::RunKey>(unsaved, unsaved_.end()));
  unsaved_.erase(unsaved, unsaved_.end());
  for (const auto& key : keys) {
    runs_.erase(key);
    dirty_.erase(key);
    residual_stale_.erase(key);
  }
  if (!keys.empty()) spdlog::info("vehicle {}: {} runs dropped from memory", input::printable(vehicle), keys.size());
}

void RunService::lost_lease(const std::string& vehicle, const std::string& reason) {
  spdlog::warn("vehicle {}: lease lost, nothing more acknowledged: {}", input::printable(vehicle), reason);
  drop(vehicle, false);  // its chunks still queued or at the committer are refused the same way
  if (lease_lost_) lease_lost_(vehicle);
}

void RunService::settle() {
  flush_pending();
  if (!unsaved_.empty()) save_folds(std::exchange(unsaved_, {}));  // no next batch to ride on
}

void RunService::publish_due(std::chrono::steady_clock::time_point now) {
  submit_pending();
  collect(false);
  collect_residual_job();
  start_residual_job();  // a run whose interval has passed since it was found stale
  // Only the changed runs are visited (a worker of 1000 vehicles ticks after every batch).
  std::vector<std::string> due;  // dirty_ is ordered by vehicle: a vehicle's runs are adjacent
  for (auto it = dirty_.begin(); it != dirty_.end();) {
    const RunState* run = find(*it);
    if (!run) {  // unloaded (a failed load): nothing left to publish
      it = dirty_.erase(it);
      continue;
    }
    if (now - run->last_published >= context_.options.publish_interval &&
        (due.empty() || due.back() != it->vehicle))
      due.push_back(it->vehicle);
    ++it;
  }
  for (const auto& vehicle : due) publish_pending(vehicle);
  // Under load the marks and checkpoints ride with the next batch of chunks; only an idle
  // worker sends them on their own (after publishing: an estimate never waits for them).
  if (pending_.empty() && in_flight_.empty() && !unsaved_.empty()) submit(pending_);
}

void RunService::record_history(const store::RunKey& key, const EstimateTables& tables) {
  context_.store.with([&](store::Store& s) { record_history(s, key, tables); });
}

void RunService::record_history(store::Store& s, const store::RunKey& key,
                                const EstimateTables& tables) {
  const auto now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::system_clock::now().time_since_epoch())
                       .count();
  for (const auto& table : tables.tables)
    s.record_estimate({key.vehicle, table.model, key.run, now, report::estimate_json(table)});
}

}  // namespace dynid::server
