#include "sqlite.hpp"

#include <sqlite3.h>

#include <utility>

#include "dynid/store/errors.hpp"

namespace dynid::store::detail {

namespace {

std::string describe(const std::string& path, std::string_view what, int rc, const char* msg) {
  return "store " + path + ": " + std::string(what) + ": " + (msg ? msg : sqlite3_errstr(rc)) +
         " (SQLite code " + std::to_string(rc) + ")";
}

[[noreturn]] void throw_for(int rc, std::string message) {
  const int primary = rc & 0xff;
  if (primary == SQLITE_CORRUPT || primary == SQLITE_NOTADB) throw CorruptionError(message, rc);
  throw StoreError(message, rc);
}

}  // namespace

Database::Database(std::string path, bool create) : path_(std::move(path)) {
  const int flags = SQLITE_OPEN_READWRITE | (create ? SQLITE_OPEN_CREATE : 0) |
                    SQLITE_OPEN_NOMUTEX | SQLITE_OPEN_EXRESCODE;
  const int rc = sqlite3_open_v2(path_.c_str(), &db_, flags, nullptr);
  if (rc != SQLITE_OK) {
    // The handle exists even on failure (unless out of memory) and carries the message.
    std::string message = describe(path_, "open", rc, db_ ? sqlite3_errmsg(db_) : nullptr);
    sqlite3_close_v2(db_);
    db_ = nullptr;
    throw_for(rc, std::move(message));
  }
  sqlite3_extended_result_codes(db_, 1);
}

Database::~Database() {
  sqlite3_close_v2(db_);
}

void Database::exec(const char* sql, std::string_view what) {
  char* message = nullptr;
  const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, &message);
  if (rc == SQLITE_OK) return;
  std::string text = describe(path_, what, rc, message);
  sqlite3_free(message);
  throw_for(sqlite3_extended_errcode(db_), std::move(text));
}

std::int64_t Database::last_insert_rowid() const {
  return sqlite3_last_insert_rowid(db_);
}

void Database::fail(int rc, std::string_view what) const {
  throw_for(rc, describe(path_, what, rc, sqlite3_errmsg(db_)));
}

Statement::Statement(Database& db, const char* sql) : db_(db), sql_(sql) {
  // SQLITE_PREPARE_PERSISTENT: these statements live as long as the store and are reused.
  const int rc =
      sqlite3_prepare_v3(db_.handle(), sql, -1, SQLITE_PREPARE_PERSISTENT, &stmt_, nullptr);
  if (rc != SQLITE_OK) db_.fail(rc, std::string("prepare ") + sql);
}

Statement::~Statement() {
  sqlite3_finalize(stmt_);
}

Statement& Statement::start() {
  // reset() repeats the last step's error, already reported by step(): ignore it here.
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
  return *this;
}

void Statement::reset() {
  sqlite3_reset(stmt_);
}

Statement& Statement::bind(int index, std::int64_t value) {
  const int rc = sqlite3_bind_int64(stmt_, index, value);
  if (rc != SQLITE_OK) db_.fail(rc, std::string("bind ") + sql_);
  return *this;
}

Statement& Statement::bind(int index, std::string_view text) {
  const int rc =
      sqlite3_bind_text64(stmt_, index, text.data(), text.size(), SQLITE_TRANSIENT, SQLITE_UTF8);
  if (rc != SQLITE_OK) db_.fail(rc, std::string("bind ") + sql_);
  return *this;
}

Statement& Statement::bind_blob(int index, std::string_view bytes) {
  // A zero-length blob must still be a blob, not NULL: data() of an empty view may be null.
  static const char empty = 0;
  const int rc = sqlite3_bind_blob64(stmt_, index, bytes.empty() ? &empty : bytes.data(),
                                     bytes.size(), SQLITE_TRANSIENT);
  if (rc != SQLITE_OK) db_.fail(rc, std::string("bind ") + sql_);
  return *this;
}

Statement& Statement::bind_null(int index) {
  const int rc = sqlite3_bind_null(stmt_, index);
  if (rc != SQLITE_OK) db_.fail(rc, std::string("bind ") + sql_);
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  db_.fail(rc, std::string("execute ") + sql_);
}

void Statement::run() {
  while (step()) {
  }
}

std::int64_t Statement::column_int(int index) const {
  return sqlite3_column_int64(stmt_, index);
}

bool Statement::column_is_null(int index) const {
  return sqlite3_column_type(stmt_, index) == SQLITE_NULL;
}

std::string Statement::column_text(int index) const {
  const auto* text = sqlite3_column_text(stmt_, index);
  const int size = sqlite3_column_bytes(stmt_, index);
  return text ? std::string(reinterpret_cast<const char*>(text), static_cast<std::size_t>(size))
              : std::string();
}

std::string Statement::column_blob(int index) const {
  const void* data = sqlite3_column_blob(stmt_, index);
  const int size = sqlite3_column_bytes(stmt_, index);
  return data ? std::string(static_cast<const char*>(data), static_cast<std::size_t>(size))
              : std::string();
}

Transaction::Transaction(Database& db)
    : db_(db), nested_(sqlite3_get_autocommit(db.handle()) == 0) {
  db_.exec(nested_ ? "SAVEPOINT dynid_nested" : "BEGIN IMMEDIATE", "begin");
}

Transaction::~Transaction() {
  // SQLite may already have rolled back by itself (e.g. after SQLITE_FULL or an I/O error);
  // only roll back a transaction that is still open, and never throw from here.
  if (open_ && !sqlite3_get_autocommit(db_.handle())) {
    sqlite3_exec(db_.handle(),
                 nested_ ? "ROLLBACK TO dynid_nested; RELEASE dynid_nested" : "ROLLBACK", nullptr,
                 nullptr, nullptr);
  }
}

void Transaction::commit() {
  db_.exec(nested_ ? "RELEASE dynid_nested" : "COMMIT", "commit");
  open_ = false;
}

}  // namespace dynid::store::detail
