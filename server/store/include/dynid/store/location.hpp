#pragma once
// Store locations: where a Store keeps its data, told by the text alone.
//
// Contract: a location that starts with "postgresql://" or "postgres://" (libpq's connection
// URI, e.g. postgresql://dynid@db.example:5432/fleet) is a PostgreSQL database; anything else
// is the path of an SQLite file. for_messages() is the location as error messages and logs
// show it: a URI's password (user:password@) is replaced by "***", nothing else changes.
#include <string>
#include <string_view>

namespace dynid::store {

bool is_postgres_uri(std::string_view location);

std::string for_messages(std::string_view location);

}  // namespace dynid::store
