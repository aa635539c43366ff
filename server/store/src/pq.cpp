#include "pq.hpp"

#include <endian.h>
#include <libpq-fe.h>

#include <cstring>
#include <utility>

#include "dynid/store/errors.hpp"

namespace dynid::store::detail::pq {

namespace {

// Type OIDs of the parameters we send (PostgreSQL's pg_type.h, stable across versions).
constexpr unsigned kBytea = 17;
constexpr unsigned kInt8 = 20;
constexpr unsigned kText = 25;

std::string trimmed(const char* message) {
  std::string text = message ? message : "";
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

// The server's message and SQLSTATE; data the server found damaged is a CorruptionError.
[[noreturn]] void throw_for(const std::string& name, std::string_view what, const PGresult* result,
                            pg_conn* conn) {
  const char* state = result ? PQresultErrorField(result, PG_DIAG_SQLSTATE) : nullptr;
  const std::string message =
      name + ": " + std::string(what) + ": " +
      trimmed(result ? PQresultErrorMessage(result) : PQerrorMessage(conn)) +
      (state ? " (SQLSTATE " + std::string(state) + ")" : std::string(" (no SQLSTATE)"));
  if (state && (std::strcmp(state, "XX001") == 0 || std::strcmp(state, "XX002") == 0))
    throw CorruptionError(message, 0);
  throw StoreError(message, 0);
}

bool succeeded(const PGresult* result) {
  const ExecStatusType status = PQresultStatus(result);
  return status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK;
}

// libpq prints the server's notices on stderr by default; the store reports what matters
// through its errors instead.
void ignore_notice(void*, const char*) {}

}  // namespace

// ---- Params ---------------------------------------------------------------------------

Params& Params::add(unsigned type, std::string value) {
  types_.push_back(type);
  lengths_.push_back(static_cast<int>(value.size()));
  formats_.push_back(1);
  values_.push_back(std::move(value));
  return *this;
}

Params& Params::i64(std::int64_t value) {
  const std::uint64_t network = htobe64(static_cast<std::uint64_t>(value));
  return add(kInt8, std::string(reinterpret_cast<const char*>(&network), sizeof network));
}

Params& Params::text(std::string_view value) {
  return add(kText, std::string(value));
}

Params& Params::bytes(std::string_view value) {
  return add(kBytea, std::string(value));
}

std::vector<const char*> Params::values() const {
  std::vector<const char*> pointers;
  pointers.reserve(values_.size());
  for (const auto& value : values_) pointers.push_back(value.data());
  return pointers;
}

// ---- Result ---------------------------------------------------------------------------

Result::~Result() {
  PQclear(result_);
}

int Result::rows() const {
  return PQntuples(result_);
}

bool Result::is_null(int row, int column) const {
  return PQgetisnull(result_, row, column) != 0;
}

std::int64_t Result::i64(int row, int column) const {
  std::uint64_t network = 0;
  if (PQgetlength(result_, row, column) != sizeof network) return 0;  // NULL: callers check
  std::memcpy(&network, PQgetvalue(result_, row, column), sizeof network);
  return static_cast<std::int64_t>(be64toh(network));
}

std::string Result::bytes(int row, int column) const {
  return std::string(PQgetvalue(result_, row, column),
                     static_cast<std::size_t>(PQgetlength(result_, row, column)));
}

// ---- Connection -----------------------------------------------------------------------

Connection::Connection(const std::string& uri, std::string name)
    : name_(std::move(name)), conn_(PQconnectdb(uri.c_str())) {
  if (!conn_ || PQstatus(conn_) != CONNECTION_OK) {
    const std::string message =
        name_ + ": connect: " + (conn_ ? trimmed(PQerrorMessage(conn_)) : "out of memory");
    PQfinish(conn_);
    conn_ = nullptr;
    throw StoreError(message, 0);
  }
  PQsetNoticeProcessor(conn_, &ignore_notice, nullptr);
}

Connection::~Connection() {
  PQfinish(conn_);
}

void Connection::exec(const char* sql, std::string_view what) {
  const Result result(PQexec(conn_, sql));
  if (!succeeded(result.get())) throw_for(name_, what, result.get(), conn_);
}

Result Connection::run(const char* sql, const Params& params) {
  const std::string& statement = prepared(sql, params);
  const auto values = params.values();
  Result result(PQexecPrepared(conn_, statement.c_str(), params.size(), values.data(),
                               params.lengths(), params.formats(), 1));
  if (!succeeded(result.get())) throw_for(name_, sql, result.get(), conn_);
  return result;
}

const std::string& Connection::prepared(const char* sql, const Params& params) {
  if (const auto it = statements_.find(std::string_view(sql)); it != statements_.end())
    return it->second;
  std::string statement = "dynid_" + std::to_string(statements_.size());
  const Result result(PQprepare(conn_, statement.c_str(), sql, params.size(), params.types()));
  if (!succeeded(result.get()))
    throw_for(name_, std::string("prepare ") + sql, result.get(), conn_);
  return statements_.emplace(sql, std::move(statement)).first->second;
}

bool Connection::in_transaction() const {
  const PGTransactionStatusType status = PQtransactionStatus(conn_);
  return status == PQTRANS_INTRANS || status == PQTRANS_INERROR || status == PQTRANS_ACTIVE;
}

// ---- Transaction ----------------------------------------------------------------------

Transaction::Transaction(Connection& connection)
    : connection_(connection), nested_(connection.in_transaction()) {
  connection_.exec(nested_ ? "SAVEPOINT dynid_nested" : "BEGIN", "begin");
}

Transaction::~Transaction() {
  // Never throws: a lost connection has ended the transaction on the server already.
  if (open_ && connection_.in_transaction()) {
    PQclear(PQexec(connection_.handle(), nested_ ? "ROLLBACK TO SAVEPOINT dynid_nested; "
                                                   "RELEASE SAVEPOINT dynid_nested"
                                                 : "ROLLBACK"));
  }
}

void Transaction::commit() {
  if (nested_) {
    connection_.exec("RELEASE SAVEPOINT dynid_nested", "commit");
    open_ = false;
    return;
  }
  // COMMIT of a transaction that an error aborted succeeds as a ROLLBACK: refuse it here.
  if (PQtransactionStatus(connection_.handle()) == PQTRANS_INERROR) {
    throw StoreError(connection_.name() + ": commit: the transaction failed earlier", 0);
  }
  const Result result(PQexec(connection_.handle(), "COMMIT"));
  if (!succeeded(result.get())) {
    throw_for(connection_.name(), "commit", result.get(), connection_.handle());
  }
  if (std::strcmp(PQcmdStatus(result.get()), "COMMIT") != 0) {
    throw StoreError(connection_.name() + ": commit: the server rolled the transaction back", 0);
  }
  open_ = false;
}

}  // namespace dynid::store::detail::pq
