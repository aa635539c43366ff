// Which backend a location opens (location.hpp), after the checks common to both.
#include "backend.hpp"
#include "dynid/error.hpp"
#include "dynid/store/location.hpp"
#include "postgres_backend.hpp"
#include "sqlite_backend.hpp"

namespace dynid::store::detail {

std::unique_ptr<Backend> open_backend(const std::string& location, const StoreOptions& options) {
  if (options.reorder_window == 0) {
    throw InputError("store " + for_messages(location) + ": reorder_window must be at least 1");
  }
  if (is_postgres_uri(location)) return std::make_unique<PostgresBackend>(location, options);
  return std::make_unique<SqliteBackend>(location, options);
}

}  // namespace dynid::store::detail
