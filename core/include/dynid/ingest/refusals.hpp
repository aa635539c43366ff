#pragma once
// Words of the server's refusals that a car acts on, in one place for both sides: the store
// writes them (server/store/src/ledger.cpp), the car's delivery reads them (car/delivery.hpp).
#include <string_view>

namespace dynid::ingest {

/// The store's refusal of a chunk whose run and sequence it already holds with other bytes
/// ("chunk V/R#S is already stored with other content"). A car refused so for a chunk of its run
/// knows the run's name is taken by another recording: nothing it sends under that name can be
/// stored, and the server's acknowledgements of that run count the other recording's chunks.
inline constexpr std::string_view kStoredWithOtherContent = "is already stored with other content";

}  // namespace dynid::ingest
