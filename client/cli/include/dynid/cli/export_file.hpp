#pragma once
// What `dynid export` writes and prints. The server answers an export with one ASAM MDF 4.10 file
// (server/export_request.hpp): one channel group per model and equation group, on the rows the
// model is fitted on. The CLI reads it back with the product's MDF4 reader (can/mdf4.hpp) before
// saying it wrote it, and writes it as it came (--format mdf4) or as one CSV table (csv).
//
// export_csv(): one table for tools that want one (MATLAB's readtable, pandas): a "time [s]"
// column over the union of every group's row times (the models share the run's decimation grid,
// so equal times are one row), then every group's columns, a channel several groups hold once
// (the groups read one preprocessed run, so they agree on it); the header names each column
// "name [unit]" ("name" when it has no unit); a cell a group has no row for is empty; values are
// written in the shortest form that reads back to the same double.
//
// An export past a reply's limit comes in parts (server/export_request.hpp): part_count() reads
// their number from the reply's format, joined_export() joins the parts' files into the one file
// the server would have written (the same bytes: tables in order, the first part's comment).
//
// export_summary(): per group its name, rows, time span and column count, and the file's
// comment (which models it holds and which it left out, and why), lines within 100 columns.
#include <cstddef>
#include <string>
#include <vector>

#include <dynid/can/mdf4.hpp>

namespace dynid::cli {

/// The most parts an export has: the server's `part` argument goes to a million.
inline constexpr std::size_t kMaxParts = 1000000;

/// N of "application/x-mdf4; part=K/N"; 1 when the format names no parts; std::runtime_error for
/// more than kMaxParts.
std::size_t part_count(const std::string& payload_format);
std::string joined_export(const std::vector<can::Mdf4File>& parts);

std::string export_csv(const can::Mdf4File& file);
std::string export_summary(const can::Mdf4File& file);

}  // namespace dynid::cli
