// The chunk path and the ledger: storing chunks in or out of order, the contiguous and folded
// marks, checkpoints and replay streams. The policies are documented in store.hpp.
#include <limits>

#include "chunk_stream_impl.hpp"
#include "dynid/ingest/chunk.hpp"
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

}  // namespace

// The stored bytes of a sequence, if any (a sequence beyond int64 is never stored).
std::optional<std::string> Store::Impl::stored_bytes(std::int64_t run_id, std::uint64_t sequence) {
  if (sequence > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
    return std::nullopt;
  }
  detail::Query query(find_chunk);
  query->bind(1, run_id).bind(2, static_cast<std::int64_t>(sequence));
  if (!query->step()) return std::nullopt;
  return query->column_blob(0);
}

// After `from` became stored next to the contiguous prefix: the new end of the prefix, past
// chunks that were stored ahead of the gap.
std::int64_t Store::Impl::advance_contiguous(std::int64_t run_id, std::int64_t from) {
  std::int64_t last = from;
  detail::Query query(chunk_exists);
  while (query->start().bind(1, run_id).bind(2, last + 1).step()) ++last;
  return last;
}

void Store::Impl::insert(const detail::RunRow& run, const ingest::Chunk& chunk,
                         const std::string& bytes) {
  insert_chunk.start()
      .bind(1, run.id)
      .bind(2, static_cast<std::int64_t>(chunk.sequence))
      .bind(3, to_db(chunk.first_sample_index, name_of({chunk.vehicle, chunk.run})))
      .bind(4, static_cast<std::int64_t>(chunk.samples.rows()))
      .bind_blob(5, bytes)
      .bind(6, static_cast<std::int64_t>(chunk.checksum))
      .bind(7, detail::now_ns())
      .run();
}

StoreChunkResult Store::store_chunk(const ingest::Chunk& chunk) {
  const detail::RunRow& run = impl_->run({chunk.vehicle, chunk.run});
  return impl_->store_valid(run, chunk,
                            ingest::validate_and_encode(chunk, run.announcement, impl_->options.limits));
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

  detail::Transaction transaction(s.db);  // rolls back on every early return and throw
  const detail::Ledger ledger = s.ledger(run.id);
  if (const auto stored = s.stored_bytes(run.id, chunk.sequence)) {
    if (*stored == bytes) return {ChunkStatus::duplicate, from_db(ledger.contiguous), {}};
    return {ChunkStatus::conflict, from_db(ledger.contiguous),
            "chunk " + label + " is already stored with other content"};
  }
  if (run.closed) throw InputError("chunk " + label + ": the run is closed");
  if (!within_window(chunk.sequence, ledger.contiguous, s.options.reorder_window)) {
    return {ChunkStatus::beyond_window, from_db(ledger.contiguous),
            "chunk " + label + " is more than " + std::to_string(s.options.reorder_window) +
                " past the contiguous prefix; resend it later"};
  }
  if (static_cast<std::int64_t>(chunk.sequence) <= ledger.contiguous) {
    throw CorruptionError("store " + s.db.path() + ": chunk " + label +
                              " is missing although the ledger counts it as stored",
                          0);
  }
  s.insert(run, chunk, bytes);
  std::int64_t contiguous = ledger.contiguous;
  if (static_cast<std::int64_t>(chunk.sequence) == contiguous + 1) {
    contiguous = s.advance_contiguous(run.id, contiguous + 1);
    s.set_contiguous.start().bind(1, run.id).bind(2, contiguous).run();
  }
  transaction.commit();
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
  return ChunkStream(std::make_unique<ChunkStream::Impl>(s.db, key, run_id, from, to));
}

void Store::mark_folded(const RunKey& key, std::uint64_t sequence) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  const std::int64_t mark = to_db(sequence, name_of(key));
  detail::Transaction transaction(s.db);
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
  s.set_folded.start().bind(1, run_id).bind(2, mark).run();
  transaction.commit();
}

void Store::save_checkpoint(const RunKey& key, std::uint64_t folded, std::string_view state) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  const std::int64_t mark = to_db(folded, name_of(key));
  const std::string where =
      "checkpoint of run " + name_of(key) + " through #" + std::to_string(folded);
  detail::Transaction transaction(s.db);
  const detail::Ledger ledger = s.ledger(run_id);
  if (mark > ledger.contiguous) throw InputError(where + ": those chunks are not all stored");
  if (detail::Query query(s.newest_checkpoint); query->bind(1, run_id).step()) {
    const std::int64_t newest = query->column_int(0);
    if (mark < newest) throw InputError(where + ": older than the latest checkpoint");
    if (mark == newest) {
      if (query->column_blob(1) == state) return;  // the same again: nothing to do
      throw InputError(where + ": a different checkpoint is already saved at that mark");
    }
  }
  s.insert_checkpoint.start()
      .bind(1, run_id)
      .bind(2, mark)
      .bind_blob(3, state)
      .bind(4, detail::crc32_of(state))
      .bind(5, detail::now_ns())
      .run();
  // Only the newest is ever loaded; if it were damaged, the chunks (the truth) replay from #0.
  s.prune_checkpoints.start().bind(1, run_id).bind(2, mark).run();
  s.set_folded.start().bind(1, run_id).bind(2, std::max(mark, ledger.folded)).run();
  transaction.commit();
}

std::optional<Checkpoint> Store::latest_checkpoint(const RunKey& key) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  detail::Query newest(s.newest_checkpoint);
  if (!newest->bind(1, run_id).step()) return std::nullopt;
  Checkpoint checkpoint{static_cast<std::uint64_t>(newest->column_int(0)), newest->column_blob(1)};
  if (detail::crc32_of(checkpoint.state) != newest->column_int(2)) {
    throw CorruptionError("store " + s.db.path() + ": checkpoint of run " + name_of(key) +
                              " through #" + std::to_string(checkpoint.folded_through) +
                              " is damaged (CRC mismatch); the chunks remain, replay from #0",
                          0);
  }
  return checkpoint;
}

}  // namespace dynid::store
