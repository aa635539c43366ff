#include "dynid/cli/export_file.hpp"

#include <cstdlib>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "dynid/report/mdf4_writer.hpp"
#include "dynid/report/text_wrap.hpp"

namespace dynid::cli {
namespace {

// Every channel group of the file as the writer's table: its master's times, and every other
// channel with its unit, comment and physical values. One reading for the CSV, the summary and
// the join of an export's parts.
std::vector<report::Mdf4Table> read_tables(const can::Mdf4File& file) {
  std::vector<report::Mdf4Table> tables;
  for (std::size_t dg = 0; dg < file.data_groups().size(); ++dg) {
    const auto& channel_groups = file.data_groups()[dg].groups;
    for (std::size_t cg = 0; cg < channel_groups.size(); ++cg) {
      const can::Mdf4ChannelGroup& group = channel_groups[cg];
      std::vector<const can::Mdf4Channel*> channels;
      std::vector<std::string> names;
      for (const can::Mdf4Channel& c : group.channels)
        if (!c.is_master()) channels.push_back(&c), names.push_back(c.name);
      can::Mdf4Signals signals = file.read_signals(dg, cg, names);
      report::Mdf4Table table{group.name, group.comment, std::move(signals.time), {}};
      for (std::size_t i = 0; i < channels.size(); ++i)
        table.columns.push_back({channels[i]->name, channels[i]->unit, channels[i]->comment,
                                 std::move(signals.values[i])});
      tables.push_back(std::move(table));
    }
  }
  return tables;
}

std::string heading(const std::string& name, const std::string& unit) {
  const std::string text = unit.empty() ? name : name + " [" + unit + "]";
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

std::size_t part_count(const std::string& payload_format) {
  const auto slash = payload_format.rfind('/');
  if (payload_format.find("; part=") == std::string::npos || slash == std::string::npos) return 1;
  const unsigned long n = std::strtoul(payload_format.c_str() + slash + 1, nullptr, 10);
  // The server numbers at most kMaxParts (its `part` check): a reply saying more is not ours.
  if (n > kMaxParts)
    throw std::runtime_error("the server's export says it has " + std::to_string(n) +
                             " parts (at most " + std::to_string(kMaxParts) + ")");
  return n == 0 ? 1 : n;
}

std::string joined_export(const std::vector<can::Mdf4File>& parts) {
  report::Mdf4Document document{parts.front().start_ns(), parts.front().comment(), {}};
  for (const can::Mdf4File& file : parts)
    for (report::Mdf4Table& table : read_tables(file)) document.tables.push_back(std::move(table));
  return report::write_mdf4(document);
}

std::string export_csv(const can::Mdf4File& file) {
  const std::vector<report::Mdf4Table> tables = read_tables(file);
  // Columns in order of first appearance, a channel several tables hold once.
  std::map<std::string, std::size_t> column_of;
  std::string header = "time [s]";
  for (const report::Mdf4Table& t : tables)
    for (const report::Mdf4Column& c : t.columns)
      if (column_of.emplace(c.name, column_of.size()).second)
        header += "," + heading(c.name, c.unit);
  std::map<double, std::vector<std::string>> rows;  // time -> cells, sorted by time
  for (const report::Mdf4Table& t : tables)
    for (std::size_t k = 0; k < t.time_s.size(); ++k) {
      auto& cells = rows[t.time_s[k]];
      cells.resize(column_of.size());
      for (const report::Mdf4Column& c : t.columns) {
        std::string& cell = cells[column_of.at(c.name)];
        if (cell.empty()) cell = fmt::format("{}", c.values[k]);
      }
    }
  std::string out = header + "\n";
  for (const auto& [time, cells] : rows) {
    out += fmt::format("{}", time);
    for (const std::string& cell : cells) out += "," + cell;
    out += "\n";
  }
  return out;
}

std::string export_summary(const can::Mdf4File& file) {
  std::string out;
  for (const report::Mdf4Table& table : read_tables(file)) {
    const auto& t = table.time_s;
    out += fmt::format("  {}: {} rows", table.name, t.size());
    if (!t.empty()) out += fmt::format(" from {:.2f} to {:.2f} s", t.front(), t.back());
    out += fmt::format(", {} columns\n", table.columns.size());
  }
  std::istringstream comment(file.comment());
  for (std::string line; std::getline(comment, line);) out += report::wrap_text("  ", line, 4);
  return out;
}

}  // namespace dynid::cli
