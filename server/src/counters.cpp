#include "dynid/server/counters.hpp"

#include <fmt/format.h>

#include <array>

#include "dynid/dds/protocol.hpp"

namespace dynid::server {

namespace {

// The fields in the order of the protocol's counter list (dynid/dds/protocol.hpp), which names
// them; one list, so the snapshot, the JSON and the slots cannot disagree.
using Field = ServerCounters::Field;
constexpr std::array<Field, dds::protocol::kServerCounters.size()> kFieldList{{
    &CounterSnapshot::announcements,
    &CounterSnapshot::rejected_announcements,
    &CounterSnapshot::chunks_stored,
    &CounterSnapshot::chunks_duplicate,
    &CounterSnapshot::chunks_rejected,
    &CounterSnapshot::chunks_folded,
    &CounterSnapshot::chunks_replayed,
    &CounterSnapshot::checkpoints,
    &CounterSnapshot::estimates_published,
    &CounterSnapshot::requests,
    &CounterSnapshot::requests_rejected,
    &CounterSnapshot::not_owned,
    &CounterSnapshot::store_errors,
    &CounterSnapshot::requests_cancelled,
}};

}  // namespace

int ServerCounters::slot(Field field) {
  static_assert(kFields == static_cast<int>(kFieldList.size()), "one slot per protocol counter");
  for (std::size_t k = 0; k < kFieldList.size(); ++k)
    if (kFieldList[k] == field) return static_cast<int>(k);
  return 0;  // unreachable: every field is listed
}

void ServerCounters::add(Field field, std::uint64_t count) {
  values_[slot(field)].fetch_add(count, std::memory_order_relaxed);
}

CounterSnapshot ServerCounters::snapshot() const {
  CounterSnapshot s;
  for (std::size_t k = 0; k < kFieldList.size(); ++k)
    s.*kFieldList[k] = values_[k].load(std::memory_order_relaxed);
  return s;
}

std::string CounterSnapshot::to_json() const {
  std::string out = "{";
  for (std::size_t k = 0; k < kFieldList.size(); ++k)
    out += fmt::format("{}\"{}\":{}", k ? "," : "", dds::protocol::kServerCounters[k].name,
                       this->*kFieldList[k]);
  return out + "}";
}

}  // namespace dynid::server
