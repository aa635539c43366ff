#include "dynid/store/chunk_stream.hpp"

#include <utility>

#include "chunk_stream_impl.hpp"
#include "support.hpp"

namespace dynid::store {

namespace {

[[noreturn]] void corrupt(const std::string& store, const RunKey& key, std::uint64_t sequence,
                          const std::string& why) {
  throw CorruptionError(store + ": chunk " + detail::name_of(key, sequence) + " is damaged: " + why,
                        0);
}

// The row's columns are a second, independent record of what was stored: the decoded chunk
// must agree with them, which catches a blob that decodes but belongs elsewhere.
void check_against_row(const std::string& db, const RunKey& key, std::uint64_t sequence,
                       const ingest::Chunk& chunk, const detail::ChunkColumns& row) {
  if (chunk.vehicle != key.vehicle || chunk.run != key.run) {
    corrupt(db, key, sequence, "it decodes as a chunk of " + chunk.vehicle + "/" + chunk.run);
  }
  if (chunk.sequence != sequence) {
    corrupt(db, key, sequence, "it decodes as sequence " + std::to_string(chunk.sequence));
  }
  if (static_cast<std::int64_t>(chunk.first_sample_index) != row.first_sample_index ||
      chunk.samples.rows() != row.rows || static_cast<std::int64_t>(chunk.checksum) != row.crc) {
    corrupt(db, key, sequence, "its first sample index, row count or CRC differs from the row's");
  }
}

}  // namespace

ChunkStream::Impl::Impl(detail::Backend& backend, RunKey run_key, std::int64_t run_id,
                        std::uint64_t from, std::uint64_t to)
    : store_name(backend.describe()),
      key(std::move(run_key)),
      expected(from),
      last(to),
      finished(from > to) {
  if (!finished) {
    rows = backend.chunk_rows(run_id, detail::to_db(from, detail::name_of(key)),
                              detail::to_db(to, detail::name_of(key)));
  }
}

ChunkStream::ChunkStream(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ChunkStream::~ChunkStream() = default;
ChunkStream::ChunkStream(ChunkStream&&) noexcept = default;
ChunkStream& ChunkStream::operator=(ChunkStream&&) noexcept = default;

std::optional<ingest::Chunk> ChunkStream::next() {
  Impl& s = *impl_;
  if (s.finished) return std::nullopt;
  const auto row = s.rows->next();
  if (!row) corrupt(s.store_name, s.key, s.expected, "missing from the store");
  const auto sequence = static_cast<std::uint64_t>(row->columns.sequence);
  if (sequence != s.expected) corrupt(s.store_name, s.key, s.expected, "missing from the store");
  ingest::Chunk chunk;
  try {
    chunk = ingest::decode_chunk(row->bytes);
  } catch (const InputError& e) {
    corrupt(s.store_name, s.key, sequence, e.what());
  }
  check_against_row(s.store_name, s.key, sequence, chunk, row->columns);
  s.finished = (sequence == s.last);
  // Done: release what the read holds (SQLite: its snapshot) now rather than when dropped.
  if (s.finished) s.rows->release();
  ++s.expected;
  return chunk;
}

}  // namespace dynid::store
