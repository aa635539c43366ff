#pragma once
// The store's schema and its migrations, private to the store.
//
// Contract: bring_up_to_date() identifies the file as a dynid store (PRAGMA application_id),
// creates the schema in an empty file, applies every migration from the file's version to the
// newest in one transaction each, and refuses (StoreError naming the file) a file that is
// another application's or was written by a newer dynid. kSchemaVersion is the newest version.
#include "sqlite.hpp"

namespace dynid::store::detail {

inline constexpr int kSchemaVersion = 3;

void bring_up_to_date(Database& db);

}  // namespace dynid::store::detail
