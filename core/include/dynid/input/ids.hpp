#pragma once
// Vehicle ids and run names: which characters they may hold.
//
// Rule: 1 to kMaxIdLength (64, the wire bound dynid_wire_kIdLength) characters of
// [A-Za-z0-9._-], the first a letter or a digit. So an id is never "." or "..", never a hidden
// file name, never a path (no '/'), never a command-line option (no leading '-'), never a DDS
// partition wildcard ('*', '?', '\'), and never carries a space, a quote or a control character
// into a log line. Every entry point checks it: the car (profile vehicle.id, --run), the server
// (announcements and requests), the engineers' CLI, the DDS partition of a vehicle.
//
// Contract: check_vehicle_id / check_run_name throw InputError "<what> '<id, escaped>': <reason>"
// (the first offending character and its position, or the length). printable() is what a message
// shows of text that failed (or may fail) the rule: printable ASCII as it is, any other byte as
// \xNN, a backslash or quote escaped, at most kMaxShown bytes followed by "...". printable_text()
// is the same for a whole message built from a file's text (a DBC or profile error): only the
// bytes outside printable ASCII are escaped, nothing is cut.
#include <cstddef>
#include <string>
#include <string_view>

namespace dynid::input {

inline constexpr std::size_t kMaxIdLength = 64;
inline constexpr std::size_t kMaxShown = 80;

/// The reason `id` breaks the rule, or "" when it follows it.
std::string id_problem(std::string_view id);

/// Throws InputError "<what> '<id>': <reason>" when `id` breaks the rule.
void check_id(std::string_view what, std::string_view id);
inline void check_vehicle_id(std::string_view id) { check_id("vehicle id", id); }
inline void check_run_name(std::string_view id) { check_id("run name", id); }

/// `text` safe for a message or a log line (see the contract above).
std::string printable(std::string_view text);
std::string printable_text(std::string_view text);

}  // namespace dynid::input
