#include "dynid/store/store.hpp"

#include <sqlite3.h>

#include <map>
#include <utility>

#include "schema.hpp"
#include "store_impl.hpp"
#include "support.hpp"

namespace dynid::store {

using detail::from_db;
using detail::name_of;
using detail::now_ns;
using detail::Statement;
using detail::to_db;

namespace {

const char* check_pragma(StoreOptions::Check check) {
  return check == StoreOptions::Check::full ? "PRAGMA integrity_check" : "PRAGMA quick_check";
}

// Runs quick_check/integrity_check; anything but a single "ok" names the file and SQLite's
// first findings.
void check_file(detail::Database& db, StoreOptions::Check check) {
  if (check == StoreOptions::Check::none) return;
  Statement statement(db, check_pragma(check));
  std::string findings;
  while (statement.step()) {
    const std::string line = statement.column_text(0);
    if (line == "ok") continue;
    if (findings.size() < 500) findings += (findings.empty() ? "" : "; ") + line;
  }
  if (!findings.empty()) {
    throw CorruptionError(
        "store " + db.path() + ": " + check_pragma(check) + " failed: " + findings, 0);
  }
}

// Switches to WAL and returns the journal mode now in force.
std::string wal_mode(detail::Database& db) {
  Statement statement(db, "PRAGMA journal_mode = WAL");
  return statement.step() ? statement.column_text(0) : std::string();
}

void configure(detail::Database& db, const StoreOptions& options) {
  if (options.reorder_window == 0) {
    throw InputError("store " + db.path() + ": reorder_window must be at least 1");
  }
  // The busy timeout first: the other pragmas may have to wait for a lock.
  const std::string busy = "PRAGMA busy_timeout = " + std::to_string(options.busy_timeout_ms);
  db.exec(busy.c_str(), "set busy timeout");
  if (wal_mode(db) != "wal") {
    throw StoreError("store " + db.path() + ": cannot switch to WAL mode", 0);
  }
  // FULL: in WAL mode, every COMMIT fsyncs the log before returning (see store.hpp).
  db.exec("PRAGMA synchronous = FULL", "set synchronous");
  db.exec("PRAGMA foreign_keys = ON", "enable foreign keys");
  if (options.max_pages > 0) {
    const std::string cap = "PRAGMA max_page_count = " + std::to_string(options.max_pages);
    db.exec(cap.c_str(), "cap the file size");
  }
  check_file(db, options.check_on_open);
  detail::bring_up_to_date(db);
}

// Folds held only in memory did not survive the previous process: the durable folded state
// is each run's latest checkpoint.
void reset_folded_marks(detail::Database& db) {
  detail::Transaction transaction(db);
  db.exec(
      "UPDATE ledger SET folded_through = coalesce((SELECT max(folded_through) FROM checkpoints "
      "c WHERE c.run_id = ledger.run_id), -1)",
      "reset folded marks");
  transaction.commit();
}

}  // namespace

detail::Configured::Configured(Database& db, const StoreOptions& options) {
  configure(db, options);
  reset_folded_marks(db);
}

// ---- runs -----------------------------------------------------------------------------

const detail::RunRow* Store::Impl::lookup(const RunKey& key) {
  if (const auto it = runs.find(key); it != runs.end()) return &it->second;
  detail::Query query(find_run);
  if (!query->bind(1, key.vehicle).bind(2, key.run).step()) return nullptr;
  detail::RunRow row;
  row.id = query->column_int(0);
  row.encoded = query->column_blob(1);
  row.closed = !query->column_is_null(3);
  if (detail::crc32_of(row.encoded) != query->column_int(2)) {
    throw CorruptionError("store " + db.path() + ": announcement of run " + name_of(key) +
                              " is damaged (CRC mismatch)",
                          0);
  }
  try {
    row.announcement = ingest::decode_announcement(row.encoded);
  } catch (const InputError& e) {
    throw CorruptionError(
        "store " + db.path() + ": announcement of run " + name_of(key) + " is damaged: " + e.what(),
        0);
  }
  return &runs.emplace(key, std::move(row)).first->second;
}

const detail::RunRow& Store::Impl::run(const RunKey& key) {
  const detail::RunRow* row = lookup(key);
  if (!row) throw InputError("run " + name_of(key) + ": unknown run (never announced)");
  return *row;
}

std::int64_t Store::Impl::vehicle_id(const std::string& vehicle) {
  detail::Query query(find_vehicle);
  if (!query->bind(1, vehicle).step()) throw InputError("vehicle " + vehicle + ": unknown vehicle");
  return query->column_int(0);
}

detail::Ledger Store::Impl::ledger(std::int64_t run_id) {
  detail::Query query(read_ledger);
  if (!query->bind(1, run_id).step()) {
    throw CorruptionError("store " + db.path() + ": run without a ledger row", 0);
  }
  return {query->column_int(0), query->column_int(1)};
}

Store::Store(const std::string& path, StoreOptions options)
    : impl_(std::make_unique<Impl>(path, std::move(options))) {}
Store::~Store() = default;
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;

const std::string& Store::path() const {
  return impl_->db.path();
}

AddRunResult Store::add_run(const ingest::RunAnnouncement& announcement) {
  announcement.validate();
  const RunKey key{announcement.vehicle, announcement.run};
  const std::string encoded = ingest::encode_announcement(announcement);
  Impl& s = *impl_;
  if (const detail::RunRow* known = s.lookup(key)) {
    if (known->encoded == encoded) return AddRunResult::already_known;
    throw InputError("run " + name_of(key) +
                     ": announced again with a different content (channels, rate or models)");
  }
  detail::Transaction transaction(s.db);
  const std::int64_t now = now_ns();
  s.insert_vehicle.start().bind(1, key.vehicle).bind(2, now).run();
  s.insert_run.start()
      .bind(1, key.vehicle)
      .bind(2, key.run)
      .bind_blob(3, encoded)
      .bind(4, detail::crc32_of(encoded))
      .bind(5, now)
      .run();
  const std::int64_t run_id = s.db.last_insert_rowid();
  s.insert_ledger.start().bind(1, run_id).run();
  transaction.commit();
  return AddRunResult::added;
}

ingest::RunAnnouncement Store::announcement(const RunKey& key) {
  return impl_->run(key).announcement;
}

void Store::close_run(const RunKey& key) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  detail::Transaction transaction(s.db);
  s.close.start().bind(1, run_id).bind(2, now_ns()).run();
  transaction.commit();
  s.runs.at(key).closed = true;
}

void Store::batch(const std::function<void(Store&)>& f) {
  if (!sqlite3_get_autocommit(impl_->db.handle()))
    throw InputError("store " + impl_->db.path() + ": batch() inside a batch");
  detail::Transaction transaction(impl_->db);
  f(*this);
  transaction.commit();
}

// ---- listings and estimates -------------------------------------------------------------

std::vector<std::string> Store::list_vehicles() {
  Statement& select = impl_->select_vehicles;
  std::vector<std::string> names;
  for (select.start(); select.step();) names.push_back(select.column_text(0));
  return names;
}

std::vector<RunInfo> Store::list_runs(const std::string& vehicle) {
  Impl& s = *impl_;
  Statement& select = s.select_runs;
  select.start().bind(1, s.vehicle_id(vehicle));
  std::vector<RunInfo> runs;
  while (select.step()) {
    runs.push_back({select.column_text(0), !select.column_is_null(1), from_db(select.column_int(2)),
                    from_db(select.column_int(3)),
                    static_cast<std::uint64_t>(select.column_int(4))});
  }
  return runs;
}

void Store::record_estimate(const EstimateRecord& estimate) {
  Impl& s = *impl_;
  if (estimate.model.empty() || estimate.scope.empty()) {
    throw InputError("estimate of vehicle " + estimate.vehicle + ": empty model or scope");
  }
  const std::int64_t vehicle = s.vehicle_id(estimate.vehicle);
  detail::Transaction transaction(s.db);
  s.insert_estimate.start()
      .bind(1, vehicle)
      .bind(2, estimate.model)
      .bind(3, estimate.scope)
      .bind(4, estimate.time_ns)
      .bind_blob(5, estimate.encoded)
      .bind(6, detail::crc32_of(estimate.encoded))
      .run();
  transaction.commit();
}

std::vector<EstimateRecord> Store::estimate_history(const std::string& vehicle,
                                                    const std::string& model) {
  Impl& s = *impl_;
  const std::int64_t vehicle_id = s.vehicle_id(vehicle);
  detail::Query select(s.select_estimates);  // may stop early on a damaged record
  select->bind(1, vehicle_id).bind(2, model);
  std::vector<EstimateRecord> history;
  while (select->step()) {
    EstimateRecord record{vehicle, model, select->column_text(0), select->column_int(1),
                          select->column_blob(2)};
    if (detail::crc32_of(record.encoded) != select->column_int(3)) {
      throw CorruptionError("store " + s.db.path() + ": estimate of " + vehicle + " " + model +
                                " (" + record.scope + ", time " + std::to_string(record.time_ns) +
                                " ns) is damaged (CRC mismatch)",
                            0);
    }
    history.push_back(std::move(record));
  }
  return history;
}

}  // namespace dynid::store
