#pragma once
// Shared by the fault-injection tests (label faults): dynid-server, dynid-car and dynid as
// processes on the client tests' loopback configuration (tests/car/client_fixture.hpp: the
// discovery tag of this test process, Child, simulated runs, the chunks the car cuts), the
// server's store read read-only after the fact, final estimates compared with those of an
// uninterrupted run, and a small real filesystem that can be filled up.
#include <gtest/gtest.h>
#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "client_fixture.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/reader.hpp"

struct sqlite3;

namespace dynid::faults {

using namespace car::testing;

inline const std::string kVehicle = "dynid-testcar";  // deploy/profiles/testcar.toml

/// dynid-server on `store` (loopback, this process's tag), its output appended to `log`.
/// `checkpoint_every` small, so kills land between and inside checkpoints.
class ServerProcess {
 public:
  ServerProcess(const std::filesystem::path& store, const std::filesystem::path& log,
                int checkpoint_every = 3);
  /// SIGKILL, reaped; false (with the status in `why`) when it had already ended otherwise.
  bool kill(std::string& why);
  /// SIGTERM and the exit status (bounded).
  std::optional<int> stop();
  Child& child() { return child_; }

 private:
  Child child_;
};

/// The vehicle's acknowledgements as the car sees them, read beside it (own participant).
class AckWatch {
 public:
  AckWatch();
  /// Waits until `run` is acknowledged through `sequence`; false at the deadline.
  bool wait(const std::string& run, std::int64_t sequence, std::chrono::milliseconds patience);
  /// Takes what arrived (waiting up to `wait` for it).
  void take(const std::string& run, std::chrono::milliseconds wait);
  /// The highest sequence of the run acknowledged so far (-1: none).
  std::int64_t highest() const { return highest_; }

 private:
  dds::Participant participant_;
  dds::Reader<dynid_wire_ChunkAck> reader_;
  std::int64_t highest_ = -1;
};

/// dynid-car's command line: replays `log` as `run` (speed 0: --fast) with the spool in
/// `spool`; an empty `log` only delivers what the spool holds.
std::vector<std::string> car_command(const std::filesystem::path& spool, const std::string& run,
                                     const std::filesystem::path& log, double speed);

/// Runs the engineers' CLI (dynid) with `args`; expects exit 0 and returns its output.
std::string dynid_cli(const std::filesystem::path& scratch, const std::vector<std::string>& args);

/// The server's store read through a read-only SQLite connection (the server stopped), so the
/// check cannot change what it checks.
class StoreReader {
 public:
  explicit StoreReader(const std::filesystem::path& file);
  ~StoreReader();
  StoreReader(const StoreReader&) = delete;
  StoreReader& operator=(const StoreReader&) = delete;

  struct Ledger {
    std::int64_t contiguous_through = -2;  // -2: no ledger row
    std::int64_t folded_through = -2;
  };
  Ledger ledger(const std::string& run);
  /// (sequence, encoded bytes) of every stored chunk of the run, by sequence.
  std::vector<std::pair<std::int64_t, std::string>> chunks(const std::string& run);
  /// The latest estimate record of each model whose scope is `run` (JSON, report::estimate_json).
  std::map<std::string, std::string> final_estimates(const std::string& run);
  /// PRAGMA quick_check's answer ("ok" when the file is sound).
  std::string quick_check();
  /// The first column of the first row of `sql` (a constant query of the test's own).
  std::int64_t integer(const char* sql);

 private:
  sqlite3* db_ = nullptr;
};

/// Every chunk of `run` stored once, sequences 0..n-1 with nothing else, bit for bit the
/// `expected` ones, and the ledger folded through the last one.
void expect_stored_once(StoreReader& store, const std::string& run,
                        const std::vector<ingest::Chunk>& expected);

/// Compares two runs' final estimates (final_estimates()): the same models, parameter names and
/// row counts, values, standard deviations and sigma within `relative` (NaN matches NaN).
/// Returns the largest relative difference seen (0 when bit for bit equal).
double expect_same_estimates(const std::map<std::string, std::string>& actual,
                             const std::map<std::string, std::string>& reference, double relative);

/// The final estimates (as final_estimates() reads them) of `chunks` processed in one go,
/// without any interruption, by the server's own processing of the run the testcar profile
/// announces (through the wire form, as the server receives it).
std::map<std::string, std::string> offline_estimates(const std::string& run, const std::vector<ingest::Chunk>& chunks);

/// A real, small filesystem: a tmpfs of `bytes` mounted on a new folder inside `parent`, in a
/// mount namespace of the calling thread's own (so it vanishes with the test process and
/// nobody else sees it; children started from this thread inherit it). fill() writes a file
/// until the filesystem reports ENOSPC; make_room() deletes it. Needs CAP_SYS_ADMIN: without
/// it the constructor throws, naming why.
class SmallDisk {
 public:
  SmallDisk(const std::filesystem::path& parent, std::uint64_t bytes);
  ~SmallDisk();
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;
  const std::filesystem::path& path() const { return path_; }
  /// Fills the filesystem up; returns the bytes written.
  std::uint64_t fill();
  void make_room();
  std::uint64_t free_bytes() const;

 private:
  std::filesystem::path path_;
};

/// The log's text from `offset` on (to look at what a process wrote since a point).
std::string text_since(const std::filesystem::path& file, std::size_t offset);

}  // namespace dynid::faults
