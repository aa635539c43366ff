#include "dynid/car/spool.hpp"

#include <sqlite3.h>

#include <chrono>
#include <ctime>

#include "dynid/error.hpp"

namespace dynid::car {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS chunks (
  id        INTEGER PRIMARY KEY AUTOINCREMENT,  -- storage order = send order
  vehicle   TEXT NOT NULL,
  run       TEXT NOT NULL,
  sequence  INTEGER NOT NULL,
  stored_at INTEGER NOT NULL,                   -- unix seconds
  data      BLOB NOT NULL,
  UNIQUE (vehicle, run, sequence));
CREATE TABLE IF NOT EXISTS acks (
  vehicle  TEXT NOT NULL,
  run      TEXT NOT NULL,
  sequence INTEGER NOT NULL,
  PRIMARY KEY (vehicle, run));
CREATE TABLE IF NOT EXISTS refused (
  vehicle    TEXT NOT NULL,
  run        TEXT NOT NULL,
  sequence   INTEGER NOT NULL,
  refused_at INTEGER NOT NULL,                  -- unix seconds
  reason     TEXT NOT NULL,
  data       BLOB NOT NULL,                     -- the chunk as the server refused it
  PRIMARY KEY (vehicle, run, sequence));
CREATE TABLE IF NOT EXISTS announcements (
  vehicle  TEXT NOT NULL,
  run      TEXT NOT NULL,
  data     BLOB NOT NULL,                       -- ingest::encode_announcement
  PRIMARY KEY (vehicle, run));
)sql";

// A failure of SQLite on `db`: SpoolWriteError when the filesystem refused a write (full, or
// an I/O error: worth retrying later), else std::runtime_error; both name the file.
[[noreturn]] void throw_sqlite(sqlite3* db, int rc, const std::string& message) {
  const int primary = rc & 0xff;
  const std::string where = std::string("spool ") + sqlite3_db_filename(db, "main") + ": ";
  if (primary == SQLITE_FULL) throw SpoolWriteError(where + "disk full (" + message + ")");
  if (primary == SQLITE_IOERR) throw SpoolWriteError(where + "write failed (" + message + ")");
  throw std::runtime_error(where + message);
}

// A prepared statement that finalizes itself; errors carry SQLite's message.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK)
      throw std::runtime_error(std::string("spool: ") + sqlite3_errmsg(db));
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& s) {
    check(sqlite3_bind_text(stmt_, i, s.data(), static_cast<int>(s.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& bind(int i, std::uint64_t v) {
    check(sqlite3_bind_int64(stmt_, i, static_cast<sqlite3_int64>(v)));
    return *this;
  }
  Statement& bind_blob(int i, const std::string& bytes) {
    check(sqlite3_bind_blob64(stmt_, i, bytes.data(), bytes.size(), SQLITE_TRANSIENT));
    return *this;
  }
  /// True while there is a row.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) throw_sqlite(db_, rc, sqlite3_errmsg(db_));
    return false;
  }
  std::uint64_t u64(int col) const { return static_cast<std::uint64_t>(sqlite3_column_int64(stmt_, col)); }
  std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_, col);
    return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(stmt_, col)))
             : std::string();
  }
  std::string blob(int col) const {
    const void* p = sqlite3_column_blob(stmt_, col);
    return p ? std::string(static_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(stmt_, col)))
             : std::string();
  }

 private:
  void check(int rc) const {
    if (rc != SQLITE_OK) throw std::runtime_error(std::string("spool: ") + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

std::string chunk_name(const std::string& vehicle, const std::string& run, std::uint64_t sequence) {
  return vehicle + "/" + run + "#" + std::to_string(sequence);
}

std::string utc(std::uint64_t unix_seconds) {
  const auto t = static_cast<std::time_t>(unix_seconds);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::uint64_t now_unix() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

}  // namespace

Spool::Spool(const std::filesystem::path& directory, std::uint64_t max_bytes)
    : file_(directory / "spool.db"), max_bytes_(max_bytes) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw std::runtime_error("spool: cannot create " + directory.string() + ": " + ec.message());
  if (sqlite3_open_v2(file_.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) != SQLITE_OK) {
    const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw std::runtime_error("spool: cannot open " + file_.string() + ": " + msg);
  }
  try {
    // FULL: a commit is fsynced before store()/acknowledge() return, also in WAL mode.
    exec("PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; PRAGMA busy_timeout=5000;");
    exec(kSchema);
    recount();
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

Spool::~Spool() { sqlite3_close(db_); }

void Spool::exec(const char* sql) const {
  char* err = nullptr;
  if (const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, &err); rc != SQLITE_OK) {
    const std::string msg = err ? err : sqlite3_errstr(rc);
    sqlite3_free(err);
    throw_sqlite(db_, rc, msg);
  }
}

std::string Spool::full_message(std::uint64_t incoming) const {
  Statement s(db_, "SELECT MIN(stored_at), COUNT(*) FROM chunks");
  s.step();
  const std::uint64_t count = s.u64(1);
  std::string since = count > 0 ? utc(s.u64(0)) : std::string("(nothing pending)");
  return "spool full: " + std::to_string(bytes_) + " bytes of " + std::to_string(max_bytes_) +
         " (a chunk of " + std::to_string(incoming) + " bytes does not fit), server unreachable since " +
         since + " (" + std::to_string(count) + " chunks unacknowledged) [" + file_.string() + "]";
}

void Spool::store(const ingest::Chunk& chunk) {
  const std::string name = chunk_name(chunk.vehicle, chunk.run, chunk.sequence);
  const std::string bytes = ingest::encode_chunk(chunk);
  if (auto acked = acknowledged(chunk.vehicle, chunk.run); acked && chunk.sequence <= *acked)
    throw InputError("spool: chunk " + name + " is already acknowledged (up to #" + std::to_string(*acked) + ")");
  {
    Statement s(db_, "SELECT data FROM chunks WHERE vehicle = ?1 AND run = ?2 AND sequence = ?3");
    s.bind(1, chunk.vehicle).bind(2, chunk.run).bind(3, chunk.sequence);
    if (s.step()) {
      if (s.blob(0) == bytes) return;  // a resend of what is already stored
      throw InputError("spool: chunk " + name + " is already stored with other content");
    }
  }
  if (bytes_ + bytes.size() > max_bytes_) throw SpoolFull(full_message(bytes.size()));
  Statement s(db_, "INSERT INTO chunks (vehicle, run, sequence, stored_at, data) VALUES (?1, ?2, ?3, ?4, ?5)");
  s.bind(1, chunk.vehicle).bind(2, chunk.run).bind(3, chunk.sequence).bind(4, now_unix()).bind_blob(5, bytes);
  s.step();  // autocommit: durable (synchronous=FULL) when this returns
  bytes_ += bytes.size();
}

void Spool::acknowledge(const std::string& vehicle, const std::string& run, std::uint64_t sequence) {
  if (auto acked = acknowledged(vehicle, run); acked && sequence <= *acked) return;
  exec("BEGIN IMMEDIATE");
  try {
    Statement a(db_, "INSERT INTO acks (vehicle, run, sequence) VALUES (?1, ?2, ?3) "
                     "ON CONFLICT (vehicle, run) DO UPDATE SET sequence = excluded.sequence");
    a.bind(1, vehicle).bind(2, run).bind(3, sequence);
    a.step();
    Statement d(db_, "DELETE FROM chunks WHERE vehicle = ?1 AND run = ?2 AND sequence <= ?3");
    d.bind(1, vehicle).bind(2, run).bind(3, sequence);
    d.step();
    // The server acknowledged the run, so it holds its announcement: keep ours only while
    // chunks remain to resend after a restart.
    Statement r(db_, "DELETE FROM announcements WHERE vehicle = ?1 AND run = ?2 AND NOT EXISTS "
                     "(SELECT 1 FROM chunks WHERE vehicle = ?1 AND run = ?2)");
    r.bind(1, vehicle).bind(2, run);
    r.step();
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
  recount();
}

void Spool::recount() {
  Statement s(db_, "SELECT COALESCE(SUM(LENGTH(data)), 0) FROM chunks");
  s.step();
  bytes_ = s.u64(0);
}

void Spool::set_aside(const ingest::Chunk& stand_in, const std::string& reason) {
  const std::string name = chunk_name(stand_in.vehicle, stand_in.run, stand_in.sequence);
  const std::string bytes = ingest::encode_chunk(stand_in);
  exec("BEGIN IMMEDIATE");
  try {
    // OR IGNORE: a chunk set aside twice keeps the bytes first refused.
    Statement m(db_,
                "INSERT OR IGNORE INTO refused (vehicle, run, sequence, refused_at, reason, data) "
                "SELECT vehicle, run, sequence, ?4, ?5, data FROM chunks "
                "WHERE vehicle = ?1 AND run = ?2 AND sequence = ?3");
    m.bind(1, stand_in.vehicle)
        .bind(2, stand_in.run)
        .bind(3, stand_in.sequence)
        .bind(4, now_unix())
        .bind(5, reason);
    m.step();
    Statement u(db_,
                "UPDATE chunks SET data = ?4 WHERE vehicle = ?1 AND run = ?2 AND sequence = ?3");
    u.bind(1, stand_in.vehicle)
        .bind(2, stand_in.run)
        .bind(3, stand_in.sequence)
        .bind_blob(4, bytes);
    u.step();
    if (sqlite3_changes(db_) == 0)
      throw InputError("spool: chunk " + name + " is not in the spool to set aside");
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
  recount();
}

std::size_t Spool::set_aside_run(const std::string& vehicle, const std::string& run,
                                 const std::string& reason) {
  std::size_t moved = 0;
  exec("BEGIN IMMEDIATE");
  try {
    Statement m(
        db_,
        "INSERT OR IGNORE INTO refused (vehicle, run, sequence, refused_at, reason, data) "
        "SELECT vehicle, run, sequence, ?3, ?4, data FROM chunks WHERE vehicle = ?1 AND run = ?2");
    m.bind(1, vehicle).bind(2, run).bind(3, now_unix()).bind(4, reason);
    m.step();
    Statement d(db_, "DELETE FROM chunks WHERE vehicle = ?1 AND run = ?2");
    d.bind(1, vehicle).bind(2, run);
    d.step();
    moved = static_cast<std::size_t>(sqlite3_changes(db_));
    Statement a(db_, "DELETE FROM announcements WHERE vehicle = ?1 AND run = ?2");
    a.bind(1, vehicle).bind(2, run);
    a.step();
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
  recount();
  return moved;
}

std::vector<RefusedEntry> Spool::refused() const {
  std::vector<RefusedEntry> out;
  Statement s(db_,
              "SELECT vehicle, run, sequence, reason FROM refused ORDER BY refused_at, vehicle, "
              "run, sequence");
  while (s.step()) out.push_back({s.text(0), s.text(1), s.u64(2), s.text(3)});
  return out;
}

std::optional<ingest::RunAnnouncement> Spool::announcement(const std::string& vehicle,
                                                           const std::string& run) const {
  Statement s(db_, "SELECT data FROM announcements WHERE vehicle = ?1 AND run = ?2");
  s.bind(1, vehicle).bind(2, run);
  if (!s.step()) return std::nullopt;
  try {
    return ingest::decode_announcement(s.blob(0));
  } catch (const InputError& e) {
    throw InputError("spool " + file_.string() + ": announcement of " + vehicle + "/" + run +
                     " is corrupted: " + e.what());
  }
}

std::optional<std::uint64_t> Spool::acknowledged(const std::string& vehicle, const std::string& run) const {
  Statement s(db_, "SELECT sequence FROM acks WHERE vehicle = ?1 AND run = ?2");
  s.bind(1, vehicle).bind(2, run);
  if (!s.step()) return std::nullopt;
  return s.u64(0);
}

void Spool::store_announcement(const ingest::RunAnnouncement& announcement) {
  const std::string bytes = ingest::encode_announcement(announcement);
  const std::string name = announcement.vehicle + "/" + announcement.run;
  {
    Statement s(db_, "SELECT data FROM announcements WHERE vehicle = ?1 AND run = ?2");
    s.bind(1, announcement.vehicle).bind(2, announcement.run);
    if (s.step()) {
      if (s.blob(0) == bytes) return;  // announced again after a restart
      throw InputError("spool: run " + name + " is already announced with another layout");
    }
  }
  Statement s(db_, "INSERT INTO announcements (vehicle, run, data) VALUES (?1, ?2, ?3)");
  s.bind(1, announcement.vehicle).bind(2, announcement.run).bind_blob(3, bytes);
  s.step();  // autocommit: durable when this returns
}

std::vector<ingest::RunAnnouncement> Spool::pending_announcements() const {
  std::vector<ingest::RunAnnouncement> out;
  Statement s(db_, "SELECT a.vehicle, a.run, a.data FROM announcements a JOIN "
                   "(SELECT vehicle, run, MIN(id) AS first FROM chunks GROUP BY vehicle, run) c "
                   "ON a.vehicle = c.vehicle AND a.run = c.run ORDER BY c.first");
  while (s.step()) {
    try {
      out.push_back(ingest::decode_announcement(s.blob(2)));
    } catch (const InputError& e) {
      throw InputError("spool " + file_.string() + ": announcement of " + s.text(0) + "/" + s.text(1) +
                       " is corrupted: " + e.what());
    }
  }
  return out;
}

std::optional<ingest::Chunk> Spool::load(const std::string& vehicle, const std::string& run,
                                         std::uint64_t sequence) const {
  Statement s(db_, "SELECT data FROM chunks WHERE vehicle = ?1 AND run = ?2 AND sequence = ?3");
  s.bind(1, vehicle).bind(2, run).bind(3, sequence);
  if (!s.step()) return std::nullopt;
  try {
    return ingest::decode_chunk(s.blob(0));
  } catch (const InputError& e) {
    throw InputError("spool " + file_.string() + ": chunk " + chunk_name(vehicle, run, sequence) +
                     " is corrupted: " + e.what());
  }
}

std::vector<ingest::Chunk> Spool::pending() const {
  std::vector<ingest::Chunk> out;
  Statement s(db_, "SELECT vehicle, run, sequence, data FROM chunks ORDER BY id");
  while (s.step()) {
    try {
      out.push_back(ingest::decode_chunk(s.blob(3)));
    } catch (const InputError& e) {
      throw InputError("spool " + file_.string() + ": chunk " + chunk_name(s.text(0), s.text(1), s.u64(2)) +
                       " is corrupted: " + e.what());
    }
  }
  return out;
}

std::vector<SpoolEntry> Spool::pending_entries() const {
  std::vector<SpoolEntry> out;
  Statement s(db_, "SELECT vehicle, run, sequence, LENGTH(data) FROM chunks ORDER BY id");
  while (s.step()) out.push_back({s.text(0), s.text(1), s.u64(2), s.u64(3)});
  return out;
}

std::uint64_t Spool::count() const {
  Statement s(db_, "SELECT COUNT(*) FROM chunks");
  s.step();
  return s.u64(0);
}

}  // namespace dynid::car
