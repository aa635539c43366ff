#include "dynid/server/counters.hpp"

#include <fmt/format.h>

#include <array>

namespace dynid::server {

namespace {

// The fields in one list, so the snapshot, the JSON and the slots cannot disagree.
using Field = ServerCounters::Field;
constexpr std::array<std::pair<const char*, Field>, 13> kFieldList{{
    {"announcements", &CounterSnapshot::announcements},
    {"rejected_announcements", &CounterSnapshot::rejected_announcements},
    {"chunks_stored", &CounterSnapshot::chunks_stored},
    {"chunks_duplicate", &CounterSnapshot::chunks_duplicate},
    {"chunks_rejected", &CounterSnapshot::chunks_rejected},
    {"chunks_folded", &CounterSnapshot::chunks_folded},
    {"chunks_replayed", &CounterSnapshot::chunks_replayed},
    {"checkpoints", &CounterSnapshot::checkpoints},
    {"estimates_published", &CounterSnapshot::estimates_published},
    {"requests", &CounterSnapshot::requests},
    {"requests_rejected", &CounterSnapshot::requests_rejected},
    {"not_owned", &CounterSnapshot::not_owned},
    {"store_errors", &CounterSnapshot::store_errors},
}};

}  // namespace

int ServerCounters::slot(Field field) {
  for (std::size_t k = 0; k < kFieldList.size(); ++k)
    if (kFieldList[k].second == field) return static_cast<int>(k);
  return 0;  // unreachable: every field is listed
}

void ServerCounters::add(Field field, std::uint64_t count) {
  values_[slot(field)].fetch_add(count, std::memory_order_relaxed);
}

CounterSnapshot ServerCounters::snapshot() const {
  CounterSnapshot s;
  for (std::size_t k = 0; k < kFieldList.size(); ++k)
    s.*kFieldList[k].second = values_[k].load(std::memory_order_relaxed);
  return s;
}

std::string CounterSnapshot::to_json() const {
  std::string out = "{";
  for (std::size_t k = 0; k < kFieldList.size(); ++k)
    out += fmt::format("{}\"{}\":{}", k ? "," : "", kFieldList[k].first, this->*kFieldList[k].second);
  return out + "}";
}

}  // namespace dynid::server
