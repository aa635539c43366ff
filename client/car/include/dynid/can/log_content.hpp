#pragma once
// What a file that is no CAN log of a format read here looks like, for the message that refuses
// it (dynid-car --replay: a file of mostly bad lines is otherwise only named by its first bad
// line, read as candump).
//
// Judged from the file's first 64 KiB: empty; compressed (gzip, zip, xz, bzip2); binary (a zero
// byte, or more than a tenth of the bytes neither printable ASCII nor UTF-8); JSON or XML; a CSV
// table (the first lines split into the same number of at least two fields by ',', ';' or tab):
// its header's columns are named, and a table without a column of times is said to have no time
// stamps, so it cannot be replayed (a replay needs each frame's time). Anything else, e.g. prose or
// a log with bad lines, gets "" (its first bad line says enough).
#include <filesystem>
#include <string>
#include <string_view>

namespace dynid::can {

/// "it looks like <what>[: <what to do>]" for `head`, the first bytes of a file, or "".
std::string describe_log_content(std::string_view head);

/// describe_log_content() of the file's first 64 KiB; "" when it cannot be read.
std::string describe_log_file(const std::filesystem::path& path);

}  // namespace dynid::can
