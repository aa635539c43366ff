#pragma once
// The state behind a ChunkStream, private to the store: the backend's rows of the range
// (backend.hpp: ChunkRows, read a bounded number at a time), and the next sequence it expects,
// which is how a missing row is noticed.
#include <cstdint>
#include <memory>
#include <string>

#include "backend.hpp"
#include "dynid/store/chunk_stream.hpp"
#include "dynid/store/store.hpp"

namespace dynid::store {

struct ChunkStream::Impl {
  Impl(detail::Backend& backend, RunKey run_key, std::int64_t run_id, std::uint64_t from,
       std::uint64_t to);

  std::string store_name;  // "store <location>", for messages
  std::unique_ptr<detail::ChunkRows> rows;
  RunKey key;
  std::uint64_t expected;
  std::uint64_t last;
  bool finished = false;
};

}  // namespace dynid::store
