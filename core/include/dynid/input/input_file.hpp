#pragma once
// Input files: what the programs read (vehicle profiles, DBC files, candump logs, Cyclone DDS
// configurations) must be regular files, so that a FIFO, a directory or a device such as
// /dev/zero is refused at once instead of blocking the reader or feeding it without end.
//
// Contract: check_input_file() throws InputError "<path>: <what>: <reason>" when the path does
// not exist, cannot be examined, is not a regular file (the reason names the kind: directory,
// FIFO, character device, ...; a symbolic link is followed), or, with max_bytes > 0, is larger
// than max_bytes. read_input_file() checks the same, then reads the whole file (the file being
// truncated or growing meanwhile is seen as a read error or cut at max_bytes + 1 and refused).
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace dynid::input {

/// Largest vehicle profile, DBC file and Cyclone configuration read whole (real DBC files are
/// up to a few MB).
inline constexpr std::uintmax_t kMaxTextFileBytes = 64ull << 20;

void check_input_file(const std::filesystem::path& path, std::string_view what, std::uintmax_t max_bytes = 0);

std::string read_input_file(const std::filesystem::path& path, std::string_view what,
                            std::uintmax_t max_bytes = kMaxTextFileBytes);

/// An output the programs write (an HTML report, a chunk file): absent, a regular file (which is
/// replaced) or a character device such as /dev/null. A FIFO would block the writer until
/// something reads it; a directory, a socket or a block device cannot hold the output:
/// InputError "<path>: <what>: is <kind>, not a regular file".
void check_output_file(const std::filesystem::path& path, std::string_view what);

}  // namespace dynid::input
