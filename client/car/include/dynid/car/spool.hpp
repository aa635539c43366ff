#pragma once
// Spool: the car's on-disk queue of chunks the server has not acknowledged yet. A chunk is
// stored before it is sent and deleted only when the server acknowledges it durably, so a lost
// link or a restart of the car loses nothing.
//
// Storage: one SQLite database (spool.db in the spool directory), WAL journal with
// synchronous=FULL, one row per chunk (vehicle, run, sequence, ingest::encode_chunk bytes,
// time stored). Chosen over an append-only file because acknowledgements delete from the
// front of many runs at once and a restart must find the unacknowledged chunks in order: SQLite
// gives atomic, fsynced inserts and deletes and ordered reads for free, and a torn write at power
// loss rolls back instead of leaving a half chunk to parse. The chunk bytes carry their own
// CRC, checked again when read back.
//
// Contract:
// - store() returns once the chunk is durable (committed, fsynced). Storing the same (vehicle,
//   run, sequence) again with identical bytes is a no-op (a resend); with other bytes, or a
//   sequence at or below the run's acknowledged one, it throws InputError.
// - Bound: payload bytes (the sum of stored encodings) never exceed max_bytes. A chunk that would
//   exceed it is not stored and SpoolFull is thrown: "spool full: N bytes of M, server
//   unreachable since <UTC time of the oldest unacknowledged chunk> (<count> chunks
//   unacknowledged)". Nothing is ever dropped to make room.
// - acknowledge(vehicle, run, s): the server holds every chunk of the run up to s durably;
//   deletes them (durably) and remembers s. Acks at or below an earlier one change nothing.
// - pending() lists the unacknowledged chunks in the order they were stored, which is sequence
//   order within a run, also after reopening the spool (a client restart).
// - A corrupted chunk read back (CRC) throws InputError naming the chunk; the spool's own I/O
//   failures throw std::runtime_error with SQLite's message and the file. A write that the
//   filesystem refuses (SQLITE_FULL: "disk full", or an I/O error) throws SpoolWriteError:
//   nothing was stored, acknowledged or deleted, and the same call can be retried once there
//   is room (Delivery holds the chunks meanwhile).
// - Announcements: store_announcement() keeps a run's announcement durably (the same bytes
//   again are a no-op; another announcement for the same vehicle and run throws InputError), so
//   a restarted client can announce its pending runs again before resending their chunks.
//   pending_announcements() lists those of runs that still have chunks in the spool, in the
//   order of their oldest chunk. An acknowledgement that leaves a run without chunks deletes its
//   announcement too: the server acknowledged the run, so it holds the announcement. Not
//   counted in bytes(): one small row per run.
// - Refused chunks: set_aside() keeps a chunk the server refuses for good (its content breaks
//   the server's rule) in a table of refused chunks with the reason, and puts a stand-in (the
//   same sequence and rows, every row invalid: delivery.hpp) in its place, so the run's later
//   chunks are not held up. set_aside_run() moves every chunk of a run the server cannot take
//   (its name holds another recording's chunks there) to that table and deletes the run's
//   announcement: nothing of it is resent at the next start, and nothing is lost. refused()
//   lists them; they are never deleted by the product and not counted in bytes().
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <dynid/ingest/chunk.hpp>
#include <dynid/ingest/run_announcement.hpp>

struct sqlite3;

namespace dynid::car {

class SpoolFull : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The spool's file could not be written (disk full, I/O error); nothing changed. The message
/// names the file and says "disk full" when that is the reason.
class SpoolWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SpoolEntry {
  std::string vehicle;
  std::string run;
  std::uint64_t sequence = 0;
  std::uint64_t bytes = 0;
};

struct RefusedEntry {
  std::string vehicle;
  std::string run;
  std::uint64_t sequence = 0;
  std::string reason;
};

class Spool {
 public:
  /// Opens (creating the directory and database if needed) the spool in `directory`.
  Spool(const std::filesystem::path& directory, std::uint64_t max_bytes);
  ~Spool();
  Spool(const Spool&) = delete;
  Spool& operator=(const Spool&) = delete;

  void store(const ingest::Chunk& chunk);
  void acknowledge(const std::string& vehicle, const std::string& run, std::uint64_t sequence);

  void store_announcement(const ingest::RunAnnouncement& announcement);
  /// Announcements of the runs with chunks in the spool, oldest pending chunk first.
  std::vector<ingest::RunAnnouncement> pending_announcements() const;
  /// One unacknowledged chunk (decoded and CRC-checked), or nothing if it is not in the spool.
  std::optional<ingest::Chunk> load(const std::string& vehicle, const std::string& run,
                                    std::uint64_t sequence) const;

  /// The stored announcement of a run, if any.
  std::optional<ingest::RunAnnouncement> announcement(const std::string& vehicle,
                                                      const std::string& run) const;

  /// Moves the chunk of stand_in's run and sequence to the refused chunks with `reason` and
  /// stores `stand_in` in its place; InputError when no such chunk is in the spool.
  void set_aside(const ingest::Chunk& stand_in, const std::string& reason);
  /// Moves every chunk of the run to the refused chunks with `reason` and deletes its
  /// announcement; returns how many chunks moved.
  std::size_t set_aside_run(const std::string& vehicle, const std::string& run,
                            const std::string& reason);
  /// The refused chunks, oldest refusal first.
  std::vector<RefusedEntry> refused() const;

  /// The unacknowledged chunks, oldest first (decoded and CRC-checked).
  std::vector<ingest::Chunk> pending() const;
  /// The same, without reading the chunk bytes.
  std::vector<SpoolEntry> pending_entries() const;
  /// The highest acknowledged sequence of a run, if any.
  std::optional<std::uint64_t> acknowledged(const std::string& vehicle, const std::string& run) const;

  std::uint64_t bytes() const { return bytes_; }
  std::uint64_t max_bytes() const { return max_bytes_; }
  std::uint64_t count() const;
  const std::filesystem::path& file() const { return file_; }

 private:
  void exec(const char* sql) const;
  void recount();
  std::string full_message(std::uint64_t incoming) const;

  std::filesystem::path file_;
  std::uint64_t max_bytes_;
  std::uint64_t bytes_ = 0;
  sqlite3* db_ = nullptr;
};

}  // namespace dynid::car
