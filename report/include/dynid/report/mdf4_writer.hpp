#pragma once
// Time-series tables as an ASAM MDF 4.10 file (.mf4): what asammdf, MATLAB's mdfRead, CANape and
// the product's own reader (can/mdf4.hpp) open. `dynid export` writes a run's channels, fitted
// values and residuals with it.
//
// Layout written (little-endian, every block 8-byte aligned): the identification ("MDF     ",
// "4.10    ", program "dynid"), ##HD (start time, the document's comment as an ##MD
// <HDcomment>), one ##FH (the tool, as the standard requires), then per table one ##DG (no record
// ids) with one sorted ##CG (its acquisition name and comment as ##TX), its channels as ##CN:
// first the master, "time" in s (sync type time), then each column, all IEEE 754 float64 with
// their name and unit (##TX) and comment (##TX, when given), and the records in one ##DT. A value
// a column does not have is NaN. No conversion blocks: the stored values are the physical ones.
//
// Contract: every column of a table has one value per time; table and column names are not
// empty; a table's column names are unique and none is "time". Otherwise std::invalid_argument
// (a caller's bug, not bad input).
#include <cstdint>
#include <string>
#include <vector>

namespace dynid::report {

struct Mdf4Column {
  std::string name;
  std::string unit;     ///< SI, e.g. "m/s"; "" for a dimensionless value
  std::string comment;  ///< what the values are, for the reader of the file; may be empty
  std::vector<double> values;
};

struct Mdf4Table {
  std::string name;            ///< the channel group's acquisition name
  std::string comment;         ///< may be empty
  std::vector<double> time_s;  ///< the master channel: seconds from the document's start
  std::vector<Mdf4Column> columns;
};

struct Mdf4Document {
  std::int64_t start_ns = 0;  ///< the measurement's start, ns since 1970 UTC (##HD)
  std::string comment;        ///< the file's comment (##HD), plain text
  std::vector<Mdf4Table> tables;
};

/// The file's bytes.
std::string write_mdf4(const Mdf4Document& document);

}  // namespace dynid::report
