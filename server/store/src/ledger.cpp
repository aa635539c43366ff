// The chunk path and the ledger: storing chunks in or out of order, the contiguous and folded
// marks, checkpoints and replay streams. The policies are documented in store.hpp.
#include <limits>

#include "chunk_stream_impl.hpp"
#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/refusals.hpp"
#include "store_impl.hpp"
#include "support.hpp"

namespace dynid::store {

using detail::from_db;
using detail::name_of;
using detail::to_db;

namespace {

bool within_window(std::uint64_t sequence, std::int64_t contiguous, std::uint64_t window) {
  const auto next = static_cast<std::uint64_t>(contiguous + 1);
  return sequence < next || sequence - next < window;
}

// The stored bytes of a sequence, if any (a sequence beyond int64 is never stored).
std::optional<std::string> stored_bytes(detail::Backend& backend, std::int64_t run_id,
                                        std::uint64_t sequence) {
  if (sequence > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    return std::nullopt;
  }
  return backend.chunk_bytes(run_id, static_cast<std::int64_t>(sequence));
}

detail::ChunkColumns columns_of(const ingest::Chunk& chunk) {
  return {static_cast<std::int64_t>(chunk.sequence),
          to_db(chunk.first_sample_index, name_of({chunk.vehicle, chunk.run})),
          static_cast<std::int64_t>(chunk.samples.rows()),
          static_cast<std::int64_t>(chunk.checksum)};
}

}  // namespace

StoreChunkResult Store::store_chunk(const ingest::Chunk& chunk) {
  const detail::RunRow& run = impl_->run({chunk.vehicle, chunk.run});
  return impl_->store_valid(
      run, chunk, ingest::validate_and_encode(chunk, run.announcement, impl_->options.limits));
}

StoreChunkResult Store::store_chunk(const ingest::ValidatedChunk& validated) {
  const ingest::Chunk& chunk = validated.chunk();
  const detail::RunRow& run = impl_->run({chunk.vehicle, chunk.run});
  if (!validated.validated_for(run.announcement, impl_->options.limits)) {
    return impl_->store_valid(
        run, chunk, ingest::validate_and_encode(chunk, run.announcement, impl_->options.limits));
  }
  return impl_->store_valid(run, chunk, validated.encoded());
}

StoreChunkResult Store::Impl::store_valid(const detail::RunRow& run, const ingest::Chunk& chunk,
                                          const std::string& bytes) {
  Impl& s = *this;
  const RunKey key{chunk.vehicle, chunk.run};
  const std::string label = name_of(key, chunk.sequence);

  const auto transaction = s.begin_write(key.vehicle);  // rolls back on every return and throw
  const detail::Ledger ledger = s.ledger(run.id);
  if (const auto stored = stored_bytes(*s.backend, run.id, chunk.sequence)) {
    if (*stored == bytes) return {ChunkStatus::duplicate, from_db(ledger.contiguous), {}};
    return {ChunkStatus::conflict, from_db(ledger.contiguous),
            "chunk " + label + " " + std::string(ingest::kStoredWithOtherContent)};
  }
  if (run.closed || ledger.closed) throw InputError("chunk " + label + ": the run is closed");
  if (!within_window(chunk.sequence, ledger.contiguous, s.options.reorder_window)) {
    return {ChunkStatus::beyond_window, from_db(ledger.contiguous),
            "chunk " + label + " is more than " + std::to_string(s.options.reorder_window) +
                " past the contiguous prefix; resend it later"};
  }
  if (static_cast<std::int64_t>(chunk.sequence) <= ledger.contiguous) {
    throw CorruptionError(
        s.name() + ": chunk " + label + " is missing although the ledger counts it as stored", 0);
  }
  s.backend->insert_chunk(run.id, columns_of(chunk), bytes, detail::now_ns());
  std::int64_t contiguous = ledger.contiguous;
  if (static_cast<std::int64_t>(chunk.sequence) == contiguous + 1) {
    contiguous = s.backend->contiguous_from(run.id, contiguous + 1);
    s.backend->set_contiguous(run.id, contiguous);
  }
  transaction->commit();
  return {ChunkStatus::stored, from_db(contiguous), {}};
}

std::optional<std::uint64_t> Store::highest_contiguous(const RunKey& key) {
  return from_db(impl_->ledger(impl_->run(key).id).contiguous);
}

std::optional<std::uint64_t> Store::folded_through(const RunKey& key) {
  return from_db(impl_->ledger(impl_->run(key).id).folded);
}

ChunkStream Store::chunks(const RunKey& key, std::uint64_t from, std::uint64_t to) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  const std::int64_t contiguous = s.ledger(run_id).contiguous;
  if (to >= from && (contiguous < 0 || to > static_cast<std::uint64_t>(contiguous))) {
    throw InputError(
        "run " + name_of(key) + ": chunks up to #" + std::to_string(to) + " requested, but only " +
        (contiguous < 0 ? std::string("none are") : "0.." + std::to_string(contiguous) + " are") +
        " stored contiguously");
  }
  return ChunkStream(std::make_unique<ChunkStream::Impl>(*s.backend, key, run_id, from, to));
}

void Store::mark_folded(const RunKey& key, std::uint64_t sequence) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  const std::int64_t mark = to_db(sequence, name_of(key));
  const auto transaction = s.begin_write(key.vehicle);
  const detail::Ledger ledger = s.ledger(run_id);
  if (mark > ledger.contiguous) {
    throw InputError("run " + name_of(key) + ": cannot mark #" + std::to_string(sequence) +
                     " folded, it is not stored contiguously");
  }
  if (mark < ledger.folded) {
    throw InputError("run " + name_of(key) + ": folded mark would move back from #" +
                     std::to_string(ledger.folded) + " to #" + std::to_string(sequence) +
                     " (chunks would be folded twice)");
  }
  s.backend->set_folded(run_id, mark);
  transaction->commit();
}

void Store::restart_folds(const std::string& vehicle) {
  Impl& s = *impl_;
  const auto transaction = s.begin_write(vehicle);
  if (const auto id = s.backend->find_vehicle(vehicle)) s.backend->restart_folds(*id);
  transaction->commit();
}

void Store::save_checkpoint(const RunKey& key, std::uint64_t folded, std::string_view state) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  const std::int64_t mark = to_db(folded, name_of(key));
  const std::string where =
      "checkpoint of run " + name_of(key) + " through #" + std::to_string(folded);
  const auto transaction = s.begin_write(key.vehicle);
  const detail::Ledger ledger = s.ledger(run_id);
  if (mark > ledger.contiguous) throw InputError(where + ": those chunks are not all stored");
  if (const auto newest = s.backend->newest_checkpoint(run_id)) {
    if (mark < newest->folded_through)
      throw InputError(where + ": older than the latest checkpoint");
    if (mark == newest->folded_through) {
      if (newest->state == state) return;  // the same again: nothing to do
      throw InputError(where + ": a different checkpoint is already saved at that mark");
    }
  }
  // Only the newest is ever loaded; if it were damaged, the chunks (the truth) replay from #0.
  s.backend->replace_checkpoints(run_id, {mark, std::string(state), detail::crc32_of(state)},
                                 detail::now_ns());
  s.backend->set_folded(run_id, std::max(mark, ledger.folded));
  transaction->commit();
}

std::optional<Checkpoint> Store::latest_checkpoint(const RunKey& key) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  auto newest = s.backend->newest_checkpoint(run_id);
  if (!newest) return std::nullopt;
  Checkpoint checkpoint{static_cast<std::uint64_t>(newest->folded_through),
                        std::move(newest->state)};
  if (detail::crc32_of(checkpoint.state) != newest->crc) {
    throw CorruptionError(s.name() + ": checkpoint of run " + name_of(key) + " through #" +
                              std::to_string(checkpoint.folded_through) +
                              " is damaged (CRC mismatch); the chunks remain, replay from #0",
                          0);
  }
  return checkpoint;
}

}  // namespace dynid::store
