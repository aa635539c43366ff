#pragma once
// Thin RAII layer over the SQLite C API, private to the store.
//
// Contract: every failing SQLite call throws StoreError (CorruptionError for SQLITE_CORRUPT and
// SQLITE_NOTADB) whose message names the database file, what was being done, SQLite's message
// and its extended result code, so a full disk or an I/O error is never reported anonymously.
// Handles and statements are closed/finalized by their destructors; a Transaction that is not
// committed rolls back when it goes out of scope, so an exception leaves nothing half-written.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

struct sqlite3;
struct sqlite3_stmt;

namespace dynid::store::detail {

class Database {
 public:
  /// Opens (creating if asked) the file; throws StoreError naming it.
  Database(std::string path, bool create);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  sqlite3* handle() const { return db_; }
  const std::string& path() const { return path_; }
  /// Runs SQL without parameters (pragmas, DDL, BEGIN/COMMIT). Never pass input data here.
  void exec(const char* sql, std::string_view what);
  /// The rowid of the last row this connection inserted.
  std::int64_t last_insert_rowid() const;
  /// Throws the error describing `rc` (with SQLite's current message) for `what`.
  [[noreturn]] void fail(int rc, std::string_view what) const;

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
};

/// A prepared statement, prepared once and reset before every use.
class Statement {
 public:
  Statement(Database& db, const char* sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  /// Resets and clears bindings; returns *this for chained binds.
  Statement& start();
  /// Resets without clearing: ends the statement's read, if a row was left pending.
  void reset();
  Statement& bind(int index, std::int64_t value);
  Statement& bind(int index, std::string_view text);
  Statement& bind_blob(int index, std::string_view bytes);
  Statement& bind_null(int index);
  /// Steps once; true when a row is available, false when done.
  bool step();
  /// Steps a statement that returns no row (INSERT/UPDATE/DELETE).
  void run();

  std::int64_t column_int(int index) const;
  bool column_is_null(int index) const;
  std::string column_text(int index) const;
  std::string column_blob(int index) const;

 private:
  Database& db_;
  sqlite3_stmt* stmt_ = nullptr;
  const char* sql_;
};

/// One use of a statement that may stop at a row: started on construction, reset on
/// destruction, so no statement is left half-stepped holding a read snapshot (which would keep
/// the log from being checkpointed, or COMMIT from succeeding after a writing pragma).
class Query {
 public:
  explicit Query(Statement& statement) : statement_(statement) { statement_.start(); }
  ~Query() { statement_.reset(); }
  Query(const Query&) = delete;
  Query& operator=(const Query&) = delete;
  Statement* operator->() { return &statement_; }

 private:
  Statement& statement_;
};

/// BEGIN IMMEDIATE ... COMMIT. Immediate so the write lock is taken up front (no upgrade
/// failure half-way). Rolls back in the destructor unless commit() succeeded.
/// Inside an open transaction (Store::batch) it is a savepoint instead: commit() releases it
/// into the enclosing transaction (durable only when that one commits), and the destructor
/// rolls back this part alone, so one refused write does not undo the others of the batch.
class Transaction {
 public:
  explicit Transaction(Database& db);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  /// COMMIT; with synchronous=FULL the WAL is fsync'd before this returns. Nested: RELEASE.
  void commit();

 private:
  Database& db_;
  bool nested_;
  bool open_ = true;
};

}  // namespace dynid::store::detail
