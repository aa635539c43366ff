#pragma once
// The store's schema in PostgreSQL and its migrations, private to the store.
//
// Contract: bring_up_to_date() creates the schema in a database (in the connection's current
// schema, the first of its search_path) that has none, applies every migration from the
// database's version to the newest in one transaction, and refuses (StoreError naming the
// store) a database whose tables of the same names are another application's, or whose
// version was written by a newer dynid. Several servers may open the same database at once: an
// advisory lock serialises their migrations, so each is applied exactly once.
#include "pq.hpp"

namespace dynid::store::detail::postgres {

inline constexpr int kSchemaVersion = 2;

void bring_up_to_date(pq::Connection& connection);

}  // namespace dynid::store::detail::postgres
