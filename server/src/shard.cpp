#include "dynid/server/shard.hpp"

#include <charconv>

#include "dynid/error.hpp"

namespace dynid::server {

std::uint64_t fnv1a64(std::string_view text) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

std::vector<std::string> Shard::foreign_vehicles(const std::vector<std::string>& vehicles) const {
  std::vector<std::string> out;
  for (const auto& v : vehicles)
    if (!owns(v)) out.push_back(v);
  return out;
}

Shard Shard::parse(std::string_view text) {
  const auto slash = text.find('/');
  Shard shard;
  const auto number = [&](std::string_view part, std::uint32_t& out) {
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), out);
    return error == std::errc() && end == part.data() + part.size() && !part.empty();
  };
  if (slash == std::string_view::npos || !number(text.substr(0, slash), shard.index) ||
      !number(text.substr(slash + 1), shard.count) || shard.count == 0 ||
      shard.index >= shard.count)
    throw InputError("--shard '" + std::string(text) + "': expected K/N with 0 <= K < N");
  return shard;
}

}  // namespace dynid::server
