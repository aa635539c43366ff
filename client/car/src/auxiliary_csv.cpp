#include "dynid/car/auxiliary_csv.hpp"

#include <limits>
#include <set>

#include <dynid/input/ids.hpp>
#include <dynid/input/number.hpp>

#include "dynid/car/ecef.hpp"
#include "dynid/error.hpp"

namespace dynid::car {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> cells(std::string_view line) {
  std::vector<std::string_view> out;
  for (;;) {
    const std::size_t comma = line.find(',');
    out.push_back(trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return out;
    line.remove_prefix(comma + 1);
  }
}

bool is_non_finite_word(std::string_view cell) {
  return cell == "nan" || cell == "NaN" || cell == "inf" || cell == "-inf";
}

}  // namespace

AuxiliaryCsvParser::AuxiliaryCsvParser(const AuxiliarySourceSpec& spec, std::string where)
    : spec_(spec), where_(std::move(where)) {}

std::size_t AuxiliaryCsvParser::column(const std::string& name) const {
  for (std::size_t i = 0; i < header_.size(); ++i)
    if (header_[i] == name) return i;
  std::string have;
  for (const auto& h : header_) have += (have.empty() ? "" : ", ") + input::printable(h);
  throw InputError(where_ + ":" + std::to_string(line_no_) + ": auxiliary source '" + spec_.name + "': no column '" +
                   name + "' in the header (columns: " + have + ")");
}

void AuxiliaryCsvParser::read_header(std::string_view text) {
  for (auto c : cells(text)) header_.emplace_back(c);
  try {
    time_column_ = column(spec_.time_column);
    for (const auto& c : spec_.channels) columns_.push_back(c.derived.empty() ? column(c.column) : 0);
    if (spec_.ecef)
      for (std::size_t i = 0; i < 3; ++i) {
        ecef_[i] = column(spec_.ecef->position[i]);
        ecef_[3 + i] = column(spec_.ecef->velocity[i]);
      }
  } catch (...) {  // nothing taken: the parser is as it was
    header_.clear();
    columns_.clear();
    throw;
  }
}

std::optional<AuxiliaryRow> AuxiliaryCsvParser::line(std::string_view text) {
  const std::size_t line_no = ++line_no_;
  if (header_.empty()) {
    if (trim(text).empty()) throw InputError(where_ + ":" + std::to_string(line_no) + ": auxiliary source '" +
                                             spec_.name + "': empty header line");
    try {
      read_header(text);
    } catch (...) {
      --line_no_;
      throw;
    }
    return std::nullopt;
  }
  if (trim(text).empty()) return std::nullopt;
  const auto fail = [&](const std::string& reason) {
    --line_no_;  // the line is not taken: a caller may give it again once it is complete
    throw InputError(where_ + ":" + std::to_string(line_no) + ": " + reason);
  };
  const std::vector<std::string_view> row = cells(text);
  if (row.size() != header_.size())
    fail(std::to_string(row.size()) + " cells, the header has " + std::to_string(header_.size()));
  const auto time = input::parse_finite(row[time_column_]);
  if (!time) fail("time '" + input::printable(row[time_column_]) + "' is not a finite number");
  const double seconds = *time * spec_.time_scale;
  if (last_time_ && seconds < *last_time_)
    fail("time " + std::to_string(seconds) + " s is before the previous row's " + std::to_string(*last_time_) +
         " s: the rows must be sorted by time");
  AuxiliaryRow out{seconds, std::vector<double>(columns_.size(), std::numeric_limits<double>::quiet_NaN())};
  std::size_t non_finite = 0;
  for (std::size_t j = 0; j < columns_.size(); ++j) {
    if (!spec_.channels[j].derived.empty()) {
      out.values[j] = derived(spec_.channels[j].derived, row);
      continue;
    }
    const std::string_view cell = row[columns_[j]];
    if (cell.empty()) continue;
    if (is_non_finite_word(cell)) {
      ++non_finite;
    } else if (const auto x = input::parse_finite(cell)) {
      out.values[j] = *x;
    } else {
      fail("column '" + spec_.channels[j].column + "': '" + input::printable(cell) + "' is not a number");
    }
  }
  if (last_time_ && seconds == *last_time_) {
    ++repeated_;
    return std::nullopt;
  }
  last_time_ = seconds;
  non_finite_ += non_finite;
  return out;
}

// The ECEF cells of the row (NaN where one is empty or not a number: no derived value).
double AuxiliaryCsvParser::derived(const std::string& quantity, const std::vector<std::string_view>& row) const {
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  std::array<double, 6> v{};
  for (std::size_t i = 0; i < 6; ++i) {
    const auto x = input::parse_finite(row[ecef_[i]]);
    if (!x) return kNone;
    v[i] = *x;
  }
  const Vec3 position{v[0], v[1], v[2]}, velocity{v[3], v[4], v[5]};
  if (quantity == "speed") return path_speed(velocity);
  return path_grade(position, velocity).value_or(kNone);
}

std::string AuxiliaryCsvParser::unmapped_columns() const {
  std::set<std::size_t> used;
  for (std::size_t j = 0; j < columns_.size(); ++j)
    if (spec_.channels[j].derived.empty()) used.insert(columns_[j]);
  if (spec_.ecef) used.insert(ecef_.begin(), ecef_.end());
  used.insert(time_column_);
  std::string ignored;
  for (std::size_t i = 0; i < header_.size(); ++i)
    if (!used.count(i)) ignored += (ignored.empty() ? "" : ", ") + input::printable(header_[i]);
  return ignored;
}

double auxiliary_si(const AuxiliarySourceSpec& spec, std::size_t ci, double value) {
  return spec.channels[ci].gain * spec.channels[ci].to_si.apply(value);
}

}  // namespace dynid::car
