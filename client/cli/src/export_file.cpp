#include "dynid/cli/export_file.hpp"

#include <cstdlib>
#include <map>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "dynid/report/mdf4_writer.hpp"

namespace dynid::cli {
namespace {

struct Group {
  std::string name;
  can::Mdf4Signals signals;
  std::vector<std::string> units;  // of signals.names
};

// Every channel group of the file with all its channels but the master, as physical values.
std::vector<Group> read_groups(const can::Mdf4File& file) {
  std::vector<Group> groups;
  for (std::size_t dg = 0; dg < file.data_groups().size(); ++dg) {
    const auto& channel_groups = file.data_groups()[dg].groups;
    for (std::size_t cg = 0; cg < channel_groups.size(); ++cg) {
      Group g{channel_groups[cg].name, {}, {}};
      std::vector<std::string> names;
      for (const can::Mdf4Channel& c : channel_groups[cg].channels) {
        if (c.is_master()) continue;
        names.push_back(c.name);
        g.units.push_back(c.unit);
      }
      g.signals = file.read_signals(dg, cg, names);
      groups.push_back(std::move(g));
    }
  }
  return groups;
}

std::string heading(const std::string& name, const std::string& unit) {
  const std::string text = unit.empty() ? name : name + " [" + unit + "]";
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// A line of the file's comment, indented, broken at spaces before 100 columns.
std::string wrapped(const std::string& line) {
  constexpr std::size_t kWidth = 100;
  std::string out, indent = "  ";
  std::size_t start = 0;
  while (line.size() - start + indent.size() > kWidth) {
    const std::size_t space = line.rfind(' ', start + kWidth - indent.size());
    if (space == std::string::npos || space <= start) break;
    out += indent + line.substr(start, space - start) + "\n";
    start = space + 1;
    indent = "    ";
  }
  return out + indent + line.substr(start) + "\n";
}

}  // namespace

std::size_t part_count(const std::string& payload_format) {
  const auto slash = payload_format.rfind('/');
  if (payload_format.find("; part=") == std::string::npos || slash == std::string::npos) return 1;
  const unsigned long n = std::strtoul(payload_format.c_str() + slash + 1, nullptr, 10);
  return n == 0 ? 1 : n;
}

std::string joined_export(const std::vector<can::Mdf4File>& parts) {
  report::Mdf4Document document{parts.front().start_ns(), parts.front().comment(), {}};
  for (const can::Mdf4File& file : parts)
    for (std::size_t dg = 0; dg < file.data_groups().size(); ++dg) {
      const auto& channel_groups = file.data_groups()[dg].groups;
      for (std::size_t cg = 0; cg < channel_groups.size(); ++cg) {
        std::vector<std::string> names;
        for (const can::Mdf4Channel& c : channel_groups[cg].channels)
          if (!c.is_master()) names.push_back(c.name);
        can::Mdf4Signals signals = file.read_signals(dg, cg, names);
        report::Mdf4Table table{
            channel_groups[cg].name, channel_groups[cg].comment, std::move(signals.time), {}};
        for (std::size_t i = 0; i < names.size(); ++i) {
          const can::Mdf4Channel& c = *channel_groups[cg].find(names[i]);
          table.columns.push_back({c.name, c.unit, c.comment, std::move(signals.values[i])});
        }
        document.tables.push_back(std::move(table));
      }
    }
  return report::write_mdf4(document);
}

std::string export_csv(const can::Mdf4File& file) {
  const std::vector<Group> groups = read_groups(file);
  // Columns in order of first appearance; each cell: (group, channel index) holding it.
  std::vector<std::string> columns;
  std::map<std::string, std::size_t> column_of;
  std::string header = "time [s]";
  for (const Group& g : groups)
    for (std::size_t c = 0; c < g.signals.names.size(); ++c)
      if (column_of.emplace(g.signals.names[c], columns.size()).second) {
        columns.push_back(g.signals.names[c]);
        header += "," + heading(g.signals.names[c], g.units[c]);
      }
  std::map<double, std::vector<std::string>> rows;  // time -> cells, sorted by time
  for (const Group& g : groups)
    for (std::size_t k = 0; k < g.signals.time.size(); ++k) {
      auto& cells = rows[g.signals.time[k]];
      cells.resize(columns.size());
      for (std::size_t c = 0; c < g.signals.names.size(); ++c) {
        std::string& cell = cells[column_of.at(g.signals.names[c])];
        if (cell.empty()) cell = fmt::format("{}", g.signals.values[c][k]);
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
  for (const Group& g : read_groups(file)) {
    const auto& t = g.signals.time;
    out += fmt::format("  {}: {} rows", g.name, t.size());
    if (!t.empty()) out += fmt::format(" from {:.2f} to {:.2f} s", t.front(), t.back());
    out += fmt::format(", {} columns\n", g.signals.names.size());
  }
  std::istringstream comment(file.comment());
  for (std::string line; std::getline(comment, line);) out += wrapped(line);
  return out;
}

}  // namespace dynid::cli
