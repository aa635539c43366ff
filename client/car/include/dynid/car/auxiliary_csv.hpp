#pragma once
// AuxiliaryCsvParser: the lines of an auxiliary CSV source (auxiliary.hpp states the format),
// one at a time, so that a whole file (read_auxiliary_csv) and a file that grows while the run is
// live (auxiliary_follower.hpp) are read by the same rules.
//
// Contract: the first line given is the header; every later line is a row. A derived channel
// (a source with ECEF columns, vehicle_profile.hpp) is computed per row from the position and
// velocity cells (ecef.hpp), in SI; a row missing one of them has no value for it. A line that breaks
// a rule throws InputError "<where>:<line>: <reason>" and leaves the parser as it was (a caller
// that stops there keeps everything before). Rows repeating the previous row's time give no
// row (counted: repeated()); a "nan"/"inf" cell is a missing sample (counted: non_finite()).
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {

/// One row of a source: its time (seconds, source clock) and one value per declared channel
/// in the column's own unit (NaN: no sample).
struct AuxiliaryRow {
  double time = 0.0;
  std::vector<double> values;
};

class AuxiliaryCsvParser {
 public:
  /// `where` names the file in every message.
  AuxiliaryCsvParser(const AuxiliarySourceSpec& spec, std::string where);

  /// The next line (without its newline). Blank lines give nothing; so does the header.
  std::optional<AuxiliaryRow> line(std::string_view text);

  bool has_header() const { return !header_.empty(); }
  std::size_t line_number() const { return line_no_; }
  std::size_t repeated() const { return repeated_; }
  std::size_t non_finite() const { return non_finite_; }
  /// Header columns the profile does not map (ignored), comma-separated; "" if none.
  std::string unmapped_columns() const;

 private:
  const AuxiliarySourceSpec& spec_;
  std::string where_;
  std::vector<std::string> header_;
  std::size_t time_column_ = 0;
  std::vector<std::size_t> columns_;  // per declared channel (derived: unused)
  std::array<std::size_t, 6> ecef_{};  // position x y z, velocity x y z
  std::optional<double> last_time_;
  std::size_t line_no_ = 0;
  std::size_t repeated_ = 0;
  std::size_t non_finite_ = 0;

  void read_header(std::string_view text);
  double derived(const std::string& quantity, const std::vector<std::string_view>& row) const;
  std::size_t column(const std::string& name) const;
};

/// A value of declared channel `ci` in SI, as the run carries it (the profile's unit and sign).
double auxiliary_si(const AuxiliarySourceSpec& spec, std::size_t ci, double value);

}  // namespace dynid::car
