#include "dynid/report/run_export.hpp"

#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "dynid/error.hpp"
#include "dynid/residual/model_fit.hpp"

namespace dynid::report {
namespace {

// The segment holding run grid index `index`: rows are built inside segments only.
const ingest::PreprocessedSegment& segment_of(
    const std::vector<ingest::PreprocessedSegment>& segments, Eigen::Index index) {
  const auto after = std::upper_bound(
      segments.begin(), segments.end(), index,
      [](Eigen::Index i, const ingest::PreprocessedSegment& s) { return i < s.first; });
  return *std::prev(after);  // fit_model built the row inside one, so one starts at or before it
}

std::string fit_comment(const residual::ModelFit& fit) {
  std::string effects;
  for (const std::string& e : fit.effects) effects += (effects.empty() ? "" : ", ") + e;
  std::string text = fit.model + " with " + (effects.empty() ? "no effect" : "effects " + effects) +
                     "; fitted by least squares on the whole run:";
  for (std::size_t p = 0; p < fit.parameters.size(); ++p)
    text += fmt::format(" {} = {:.6g} +- {:.2g} {};", fit.parameters[p].name,
                        fit.estimate.value(static_cast<Eigen::Index>(p)),
                        fit.estimate.standard_deviation(static_cast<Eigen::Index>(p)),
                        fit.parameters[p].unit);
  return text;
}

std::vector<double> to_vector(const Eigen::VectorXd& v) {
  return {v.data(), v.data() + v.size()};
}

}  // namespace

std::vector<Mdf4Table> export_tables(const model::Model& model,
                                     const std::vector<std::string>& effects,
                                     const std::vector<ingest::PreprocessedSegment>& segments,
                                     double sample_rate_hz, int odmf) {
  residual::ModelFit fit;
  std::set<std::string> read;
  {
    // The channels the model and its effects look up are the ones its rows are made of.
    model::ChannelLookupProbe probe;
    fit = residual::fit_model(model, effects, segments, sample_rate_hz, odmf);
    read = probe.looked_up();
  }
  const model::ChannelSet& first = segments.front().channels;
  std::vector<std::string> channels;
  for (const std::string& name : first.names())
    if (read.count(name) > 0) channels.push_back(name);
  const std::string comment = fit_comment(fit);
  std::vector<Mdf4Table> tables;
  for (const residual::ResidualSeries& s : fit.series) {
    if (s.time_s.empty()) continue;
    const std::string name = fit.model + "." + s.group;
    Mdf4Table table{name, comment, s.time_s, {}};
    for (const std::string& channel : channels) {
      Mdf4Column column{channel, first.unit(channel), "preprocessed as the model read it", {}};
      column.values.reserve(s.grid_index.size());
      for (const Eigen::Index index : s.grid_index) {
        const ingest::PreprocessedSegment& segment = segment_of(segments, index);
        column.values.push_back(segment.channels[channel](index - segment.first));
      }
      table.columns.push_back(std::move(column));
    }
    const std::string unit = model.group_unit(s.group);
    table.columns.push_back({name + ".measured", unit,
                             "the measured side y of the model's equation", to_vector(s.measured)});
    table.columns.push_back({name + ".fitted", unit,
                             "W x: the model's value at the fitted parameters",
                             to_vector(s.measured - s.residual)});
    table.columns.push_back({name + ".residual", unit, "y - W x", to_vector(s.residual)});
    tables.push_back(std::move(table));
  }
  return tables;
}

std::string export_comment(const std::string& run_name, const std::string& exported,
                           const std::string& left_out) {
  return "dynid export of run " + run_name +
         "\ntimes: s from the run's start (the run carries no wall-clock time)\nmodels: " +
         exported + (left_out.empty() ? "" : "\nnot exported: " + left_out);
}

std::vector<std::vector<Mdf4Table>> export_parts(std::vector<Mdf4Table> tables,
                                                 std::size_t max_bytes,
                                                 const std::string& comment) {
  // A file's size is its header's plus each table's blocks, whatever else the file holds.
  Mdf4Document document{0, comment, {}};
  const std::size_t header = write_mdf4(document).size();
  std::vector<std::vector<Mdf4Table>> parts;
  std::size_t size = 0;
  for (Mdf4Table& table : tables) {
    document.tables = {table};
    const std::size_t bytes = write_mdf4(document).size() - header;
    if (header + bytes > max_bytes)
      throw InputError(fmt::format("table {} alone is {:.1f} MiB, past a reply's {:.0f} MiB",
                                   table.name, static_cast<double>(header + bytes) / (1 << 20),
                                   static_cast<double>(max_bytes) / (1 << 20)));
    if (parts.empty() || size + bytes > max_bytes) {
      parts.emplace_back();
      size = header;
    }
    parts.back().push_back(std::move(table));
    size += bytes;
  }
  return parts;
}

}  // namespace dynid::report
