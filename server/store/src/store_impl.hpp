#pragma once
// The state behind a Store, private to the store: its backend (the engine that reads and
// writes rows, backend.hpp), its options, and a cache of the runs looked up so that
// store_chunk does not decode the announcement again for every chunk.
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "backend.hpp"
#include "dynid/store/store.hpp"

namespace dynid::store {

namespace detail {

struct RunRow {
  std::int64_t id = 0;
  ingest::RunAnnouncement announcement;
  std::string encoded;
  bool closed = false;
};

}  // namespace detail

struct Store::Impl {
  Impl(std::unique_ptr<detail::Backend> engine, StoreOptions store_options);

  std::unique_ptr<detail::Backend> backend;
  StoreOptions options;
  std::map<RunKey, detail::RunRow> runs;  // cache of runs looked up; written only after a commit

  /// "store <location>", for messages.
  const std::string& name() const { return backend->describe(); }
  /// The run, from the cache or the backend (then cached); nullptr if never announced.
  const detail::RunRow* lookup(const RunKey& key);
  const detail::RunRow& run(const RunKey& key);
  std::int64_t vehicle_id(const std::string& vehicle);
  detail::Ledger ledger(std::int64_t run_id);
  /// A write transaction for the vehicle's data; fenced by its lease when options.holder is set
  /// (store.hpp, Leases): NotHolderError, nothing written, unless the holder holds it.
  std::unique_ptr<detail::Backend::Transaction> begin_write(const std::string& vehicle);
  /// store_chunk after validation; `bytes` is encode_chunk(chunk) (Ordering in store.hpp).
  StoreChunkResult store_valid(const detail::RunRow& run, const ingest::Chunk& chunk,
                               const std::string& bytes);
};

}  // namespace dynid::store
