#pragma once
// Thin RAII layer over libpq (PostgreSQL's C client), private to the store.
//
// Contract:
// - Every failing call throws StoreError whose message names the store (its URI without the
//   password), what was being done, the server's message and its SQLSTATE; CorruptionError for
//   SQLSTATE class XX data_corrupted/index_corrupted. A lost connection is a StoreError too.
// - Statements are prepared once per connection (on first use) and run with their parameters
//   and results in PostgreSQL's binary format, so blobs travel as they are (no escaping) and
//   integers need no parsing. Every parameter's type is declared (Params), so what a statement
//   receives never depends on the server's type inference.
// - A Transaction that is not committed rolls back when it goes out of scope; inside an open
//   transaction it is a savepoint (the same nesting as sqlite.hpp's). commit() throws if the
//   server ended the transaction in another way (an earlier error made COMMIT a rollback).
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

struct pg_conn;
struct pg_result;

namespace dynid::store::detail::pq {

/// The parameters of one statement, in binary format with their declared types.
class Params {
 public:
  Params& i64(std::int64_t value);
  Params& text(std::string_view value);
  Params& bytes(std::string_view value);

  int size() const { return static_cast<int>(types_.size()); }
  const unsigned* types() const { return types_.data(); }
  /// Pointers into the values, valid while this Params lives and is not changed.
  std::vector<const char*> values() const;
  const int* lengths() const { return lengths_.data(); }
  const int* formats() const { return formats_.data(); }

 private:
  Params& add(unsigned type, std::string value);
  std::vector<unsigned> types_;
  std::vector<std::string> values_;
  std::vector<int> lengths_;
  std::vector<int> formats_;
};

/// A statement's result in binary format; owns the PGresult.
class Result {
 public:
  explicit Result(pg_result* result) : result_(result) {}
  ~Result();
  Result(Result&& other) noexcept : result_(other.result_) { other.result_ = nullptr; }
  Result& operator=(Result&&) = delete;
  Result(const Result&) = delete;
  Result& operator=(const Result&) = delete;

  pg_result* get() const { return result_; }
  int rows() const;
  bool is_null(int row, int column) const;
  /// A bigint column (8 bytes, network order).
  std::int64_t i64(int row, int column) const;
  /// A text or bytea column: its bytes as they are.
  std::string bytes(int row, int column) const;

 private:
  pg_result* result_;
};

class Connection {
 public:
  /// Connects to `uri`; `name` ("store <uri without password>") prefixes every message.
  Connection(const std::string& uri, std::string name);
  ~Connection();
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  const std::string& name() const { return name_; }
  /// Runs SQL without parameters (SET, DDL, BEGIN/COMMIT). Never pass input data here.
  void exec(const char* sql, std::string_view what);
  /// Runs `sql` (prepared on first use with these parameter types) and returns its rows.
  Result run(const char* sql, const Params& params);
  /// True while a transaction is open (also one that failed and awaits its rollback).
  bool in_transaction() const;
  pg_conn* handle() const { return conn_; }

 private:
  const std::string& prepared(const char* sql, const Params& params);
  std::string name_;
  pg_conn* conn_ = nullptr;
  std::map<std::string, std::string, std::less<>> statements_;  // SQL -> prepared name
};

/// BEGIN ... COMMIT, or a savepoint inside an open transaction (see the contract above).
class Transaction {
 public:
  explicit Transaction(Connection& connection);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  /// COMMIT (durable once it returns: synchronous_commit is on); nested: RELEASE.
  void commit();

 private:
  Connection& connection_;
  bool nested_;
  bool open_ = true;
};

}  // namespace dynid::store::detail::pq
