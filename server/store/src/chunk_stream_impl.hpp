#pragma once
// The state behind a ChunkStream, private to the store: its own prepared statement over the
// store's connection (so two streams, or a stream and the store's writes, never share one),
// and the next sequence it expects, which is how a missing row is noticed.
#include <cstdint>

#include "dynid/store/chunk_stream.hpp"
#include "dynid/store/store.hpp"
#include "sqlite.hpp"

namespace dynid::store {

struct ChunkStream::Impl {
  Impl(detail::Database& database, RunKey run_key, std::int64_t run_id, std::uint64_t from,
       std::uint64_t to);

  detail::Database& db;
  detail::Statement select;
  RunKey key;
  std::uint64_t expected;
  std::uint64_t last;
  bool finished = false;
};

}  // namespace dynid::store
