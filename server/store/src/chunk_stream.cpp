#include "dynid/store/chunk_stream.hpp"

#include <utility>

#include "chunk_stream_impl.hpp"
#include "support.hpp"

namespace dynid::store {

namespace {

[[noreturn]] void corrupt(const detail::Database& db, const RunKey& key, std::uint64_t sequence,
                          const std::string& why) {
  throw CorruptionError(
      "store " + db.path() + ": chunk " + detail::name_of(key, sequence) + " is damaged: " + why,
      0);
}

// The row's columns are a second, independent record of what was stored: the decoded chunk
// must agree with them, which catches a blob that decodes but belongs elsewhere.
void check_against_row(const detail::Database& db, const RunKey& key, std::uint64_t sequence,
                       const ingest::Chunk& chunk, const detail::Statement& row) {
  if (chunk.vehicle != key.vehicle || chunk.run != key.run) {
    corrupt(db, key, sequence, "it decodes as a chunk of " + chunk.vehicle + "/" + chunk.run);
  }
  if (chunk.sequence != sequence) {
    corrupt(db, key, sequence, "it decodes as sequence " + std::to_string(chunk.sequence));
  }
  if (static_cast<std::int64_t>(chunk.first_sample_index) != row.column_int(1) ||
      chunk.samples.rows() != row.column_int(2) ||
      static_cast<std::int64_t>(chunk.checksum) != row.column_int(4)) {
    corrupt(db, key, sequence, "its first sample index, row count or CRC differs from the row's");
  }
}

}  // namespace

ChunkStream::Impl::Impl(detail::Database& database, RunKey run_key, std::int64_t run_id,
                        std::uint64_t from, std::uint64_t to)
    : db(database),
      select(database,
             "SELECT sequence, first_sample_index, rows, bytes, crc FROM chunks "
             "WHERE run_id = ?1 AND sequence BETWEEN ?2 AND ?3 ORDER BY sequence"),
      key(std::move(run_key)),
      expected(from),
      last(to),
      finished(from > to) {
  select.start()
      .bind(1, run_id)
      .bind(2, detail::to_db(from, detail::name_of(key)))
      .bind(3, detail::to_db(to, detail::name_of(key)));
}

ChunkStream::ChunkStream(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ChunkStream::~ChunkStream() = default;
ChunkStream::ChunkStream(ChunkStream&&) noexcept = default;
ChunkStream& ChunkStream::operator=(ChunkStream&&) noexcept = default;

std::optional<ingest::Chunk> ChunkStream::next() {
  Impl& s = *impl_;
  if (s.finished) return std::nullopt;
  if (!s.select.step()) corrupt(s.db, s.key, s.expected, "missing from the store");
  const auto sequence = static_cast<std::uint64_t>(s.select.column_int(0));
  if (sequence != s.expected) corrupt(s.db, s.key, s.expected, "missing from the store");
  ingest::Chunk chunk;
  try {
    chunk = ingest::decode_chunk(s.select.column_blob(3));
  } catch (const InputError& e) {
    corrupt(s.db, s.key, sequence, e.what());
  }
  check_against_row(s.db, s.key, sequence, chunk, s.select);
  s.finished = (sequence == s.last);
  // Done: release the statement's read snapshot now rather than when the stream is dropped.
  if (s.finished) s.select.start();
  ++s.expected;
  return chunk;
}

}  // namespace dynid::store
