#pragma once
// Helpers for the store tests: a temporary folder removed afterwards, and announcements and
// chunks whose content follows from their sequence, so a test can tell what a stored chunk
// must contain without keeping it.
#include <cstdint>
#include <filesystem>
#include <string>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/store/store.hpp"
#include "temp_dir.hpp"

namespace dynid::store::test {

using ::dynid::test::TempDir;

/// Three channels (speed, yaw rate, steering angle) at 100 Hz, one lateral_bicycle model.
ingest::RunAnnouncement announcement(const std::string& vehicle, const std::string& run);

/// A sealed chunk of `rows` rows; its values depend on sequence and `variant`.
ingest::Chunk chunk(const std::string& vehicle, const std::string& run, std::uint64_t sequence,
                    int rows = 10, int variant = 0);

/// True when both chunks hold the same fields, bit for bit.
bool same(const ingest::Chunk& a, const ingest::Chunk& b);

/// Overwrites bytes of a file in place.
void overwrite(const std::string& path, std::uint64_t offset, const std::string& bytes);
/// The offset of the first occurrence of `needle` in the file; fails the test when absent.
std::uint64_t find_in_file(const std::string& path, const std::string& needle);

}  // namespace dynid::store::test
