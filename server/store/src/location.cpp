#include "dynid/store/location.hpp"

namespace dynid::store {

bool is_postgres_uri(std::string_view location) {
  return location.starts_with("postgresql://") || location.starts_with("postgres://");
}

std::string for_messages(std::string_view location) {
  if (!is_postgres_uri(location)) return std::string(location);
  // The userinfo is what lies between "//" and the first '@' before any '/', '?' or '#'.
  const std::size_t start = location.find("//") + 2;
  const std::size_t end = location.find_first_of("/?#", start);
  const std::size_t at = location.substr(0, end).rfind('@');
  if (at == std::string_view::npos || at < start) return std::string(location);
  const std::size_t colon = location.substr(0, at).find(':', start);
  if (colon == std::string_view::npos) return std::string(location);
  return std::string(location.substr(0, colon + 1)) + "***" + std::string(location.substr(at));
}

}  // namespace dynid::store
