// Store: runs, listings and estimates, over whichever backend the location selects. The chunk
// path and the ledger are in ledger.cpp; the policies are documented in store.hpp.
#include "dynid/store/store.hpp"

#include <utility>

#include "store_impl.hpp"
#include "support.hpp"

namespace dynid::store {

using detail::from_db;
using detail::name_of;
using detail::now_ns;

Store::Impl::Impl(std::unique_ptr<detail::Backend> engine, StoreOptions store_options)
    : backend(std::move(engine)), options(std::move(store_options)) {}

// ---- runs -----------------------------------------------------------------------------

const detail::RunRow* Store::Impl::lookup(const RunKey& key) {
  if (const auto it = runs.find(key); it != runs.end()) return &it->second;
  const auto stored = backend->find_run(key);
  if (!stored) return nullptr;
  detail::RunRow row{stored->id, {}, stored->encoded, stored->closed};
  if (detail::crc32_of(row.encoded) != stored->crc) {
    throw CorruptionError(
        name() + ": announcement of run " + name_of(key) + " is damaged (CRC mismatch)", 0);
  }
  try {
    row.announcement = ingest::decode_announcement(row.encoded);
  } catch (const InputError& e) {
    throw CorruptionError(
        name() + ": announcement of run " + name_of(key) + " is damaged: " + e.what(), 0);
  }
  return &runs.emplace(key, std::move(row)).first->second;
}

const detail::RunRow& Store::Impl::run(const RunKey& key) {
  const detail::RunRow* row = lookup(key);
  if (!row) throw InputError("run " + name_of(key) + ": unknown run (never announced)");
  return *row;
}

std::int64_t Store::Impl::vehicle_id(const std::string& vehicle) {
  const auto id = backend->find_vehicle(vehicle);
  if (!id) throw InputError("vehicle " + vehicle + ": unknown vehicle");
  return *id;
}

detail::Ledger Store::Impl::ledger(std::int64_t run_id) {
  const auto row = backend->ledger(run_id);
  if (!row) throw CorruptionError(name() + ": run without a ledger row", 0);
  return *row;
}

namespace {

// The lease as a refused write describes it.
std::string describe(const std::optional<detail::LeaseState>& state) {
  if (!state) return "no lease";
  std::string text = "held by " + state->lease.holder;
  if (state->remaining_ns <= 0)
    text += ", expired " + std::to_string(-state->remaining_ns / 1000000) + " ms ago";
  return text;
}

}  // namespace

std::unique_ptr<detail::Backend::Transaction> Store::Impl::begin_write(const std::string& vehicle) {
  auto transaction = backend->begin();
  if (options.holder.empty()) return transaction;
  const auto state = backend->lease_for_write(vehicle);
  if (state && state->lease.holder == options.holder && state->remaining_ns > 0) return transaction;
  throw NotHolderError(name() + ": vehicle " + vehicle + ": " + options.holder +
                       " does not hold its lease (" + describe(state) + "); nothing written");
}

Store::Store(const std::string& location, StoreOptions options)
    : impl_(std::make_unique<Impl>(detail::open_backend(location, options), options)) {
  if (impl_->options.shared || !impl_->options.holder.empty()) return;  // each holder restarts what it takes
  const auto transaction = impl_->backend->begin();
  impl_->backend->restart_folds(std::nullopt);
  transaction->commit();
}
Store::~Store() = default;
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;

const std::string& Store::path() const {
  return impl_->backend->location();
}

AddRunResult Store::add_run(const ingest::RunAnnouncement& announcement) {
  announcement.validate();
  const RunKey key{announcement.vehicle, announcement.run};
  const std::string encoded = ingest::encode_announcement(announcement);
  Impl& s = *impl_;
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (const detail::RunRow* known = s.lookup(key)) {
      if (known->encoded == encoded) return AddRunResult::already_known;
      throw InputError("run " + name_of(key) +
                       ": announced again with a different content (channels, rate or models)");
    }
    const auto transaction = s.begin_write(key.vehicle);
    const auto added = s.backend->insert_run(key, encoded, detail::crc32_of(encoded), now_ns());
    transaction->commit();
    if (added) return AddRunResult::added;
    // Another connection added it between the lookup and the insert: compare with theirs.
  }
  throw StoreError(s.name() + ": run " + name_of(key) + " could not be added nor found", 0);
}

ingest::RunAnnouncement Store::announcement(const RunKey& key) {
  return impl_->run(key).announcement;
}

void Store::close_run(const RunKey& key) {
  Impl& s = *impl_;
  const std::int64_t run_id = s.run(key).id;
  const auto transaction = s.begin_write(key.vehicle);
  s.backend->close_run(run_id, now_ns());
  transaction->commit();
  s.runs.at(key).closed = true;
}

void Store::batch(const std::function<void(Store&)>& f) {
  if (impl_->backend->in_transaction())
    throw InputError(impl_->name() + ": batch() inside a batch");
  const auto transaction = impl_->backend->begin();
  f(*this);
  transaction->commit();
}

// ---- leases ------------------------------------------------------------------------------

Lease Store::acquire_lease(const std::string& vehicle, const std::string& holder,
                           std::chrono::milliseconds ttl) {
  if (vehicle.empty() || holder.empty() || ttl.count() <= 0) {
    throw InputError(impl_->name() + ": lease of vehicle '" + vehicle + "' for '" + holder +
                     "': needs a vehicle, a holder and a positive duration");
  }
  const auto transaction = impl_->backend->begin();
  Lease lease = impl_->backend->acquire_lease(
      vehicle, holder, std::chrono::duration_cast<std::chrono::nanoseconds>(ttl).count());
  transaction->commit();
  return lease;
}

void Store::release_lease(const std::string& vehicle, const std::string& holder) {
  const auto transaction = impl_->backend->begin();
  impl_->backend->release_lease(vehicle, holder);
  transaction->commit();
}

std::vector<Lease> Store::leases() {
  return impl_->backend->leases();
}

// ---- listings and estimates -------------------------------------------------------------

std::vector<std::string> Store::list_vehicles() {
  return impl_->backend->vehicles();
}

std::vector<RunInfo> Store::list_runs(const std::string& vehicle) {
  return impl_->backend->runs(impl_->vehicle_id(vehicle));
}

void Store::record_estimate(const EstimateRecord& estimate) {
  Impl& s = *impl_;
  if (estimate.model.empty() || estimate.scope.empty()) {
    throw InputError("estimate of vehicle " + estimate.vehicle + ": empty model or scope");
  }
  const std::int64_t vehicle = s.vehicle_id(estimate.vehicle);
  const auto transaction = s.begin_write(estimate.vehicle);
  s.backend->insert_estimate(vehicle, estimate, detail::crc32_of(estimate.encoded));
  transaction->commit();
}

std::vector<EstimateRecord> Store::estimate_history(const std::string& vehicle,
                                                    const std::string& model) {
  Impl& s = *impl_;
  std::vector<EstimateRecord> history;
  for (auto& row : s.backend->estimates(s.vehicle_id(vehicle), model)) {
    if (detail::crc32_of(row.encoded) != row.crc) {
      throw CorruptionError(s.name() + ": estimate of " + vehicle + " " + model + " (" + row.scope +
                                ", time " + std::to_string(row.time_ns) +
                                " ns) is damaged (CRC mismatch)",
                            0);
    }
    history.push_back({vehicle, model, std::move(row.scope), row.time_ns, std::move(row.encoded)});
  }
  return history;
}

}  // namespace dynid::store
