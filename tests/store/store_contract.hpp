#pragma once
// The store's contract suite (store.hpp), written once and run against every backend: each
// TEST_P of test_store_roundtrip/order/batch/bad_input/leases.cpp opens its stores through
// StoreContract::open() at a location of the engine it is instantiated with. test_store
// instantiates it for SQLite (test_store_sqlite.cpp), test_store_postgres for PostgreSQL on a
// server it starts itself (test_store_postgres.cpp, label `cluster`).
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <utility>

#include "dynid/store/store.hpp"
#include "store_test_support.hpp"

namespace dynid::store::test {

struct Engine {
  const char* name;
  /// A location holding no store yet (an SQLite file in `dir`, a new PostgreSQL database).
  std::string (*fresh_location)(const TempDir& dir);
};

class StoreContract : public ::testing::TestWithParam<Engine> {
 protected:
  /// The test's location: the same one every call, so a test can close and reopen its store.
  const std::string& location() {
    if (location_.empty()) location_ = GetParam().fresh_location(dir_);
    return location_;
  }
  Store open(StoreOptions options = {}) { return Store(location(), std::move(options)); }

 private:
  TempDir dir_;
  std::string location_;
};

/// What gtest (and so ctest's test list) prints for the parameter.
inline void PrintTo(const Engine& engine, std::ostream* out) {
  *out << engine.name;
}

inline std::string engine_name(const ::testing::TestParamInfo<Engine>& info) {
  return info.param.name;
}

// ---- the suites of the contract (complete here: every binary instantiates them) ----

class StoreRoundTrip : public StoreContract {};
class StoreBatch : public StoreContract {};
class StoreLeases : public StoreContract {};

/// One run, in a store whose reorder window is 8 (test_store_order.cpp).
class StoreOrder : public StoreContract {
 protected:
  void SetUp() override {
    StoreOptions o;
    o.reorder_window = 8;
    store_.emplace(open(o));
    store_->add_run(announcement("proto-17", "run-1"));
  }
  StoreChunkResult put(std::uint64_t sequence, int variant = 0) {
    return store_->store_chunk(chunk("proto-17", "run-1", sequence, 10, variant));
  }
  std::uint64_t stored_count() { return store_->list_runs("proto-17").at(0).chunks_stored; }

  std::optional<Store> store_;
};

/// One run with its chunk #0; whatever is rejected must leave exactly that
/// (test_store_bad_input.cpp).
class StoreBadInput : public StoreContract {
 protected:
  void SetUp() override {
    store_.emplace(open());
    store_->add_run(announcement("proto-17", "run-1"));
    store_->store_chunk(chunk("proto-17", "run-1", 0));
  }
  void expect_unchanged();
  void expect_rejected(const ingest::Chunk& c, const std::string& words);

  std::optional<Store> store_;
};

}  // namespace dynid::store::test

/// Instantiates every suite of the contract for one engine (in one test binary).
#define DYNID_INSTANTIATE_STORE_CONTRACT(prefix, engine)                                    \
  INSTANTIATE_TEST_SUITE_P(prefix, StoreRoundTrip, ::testing::Values(engine), engine_name); \
  INSTANTIATE_TEST_SUITE_P(prefix, StoreOrder, ::testing::Values(engine), engine_name);     \
  INSTANTIATE_TEST_SUITE_P(prefix, StoreBatch, ::testing::Values(engine), engine_name);     \
  INSTANTIATE_TEST_SUITE_P(prefix, StoreBadInput, ::testing::Values(engine), engine_name);  \
  INSTANTIATE_TEST_SUITE_P(prefix, StoreLeases, ::testing::Values(engine), engine_name)
