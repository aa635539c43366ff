#include "dynid/car/auxiliary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>

#include <dynid/input/ids.hpp>
#include <dynid/input/input_file.hpp>
#include <dynid/input/number.hpp>

#include <dynid/can/mdf4.hpp>

#include "dynid/car/auxiliary_csv.hpp"
#include "dynid/car/log_source.hpp"
#include "dynid/car/signal_mapper.hpp"
#include "dynid/error.hpp"

namespace dynid::car {
namespace {

std::string fmt(double v, int digits = 3) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%+.*f", digits, v);
  return buf;
}

// "offset -0.215 +- 0.014 s at the start, -0.189 +- 0.014 s at the end (drift +0.00046 +- 0.00035 s/s)"
std::string drift_text(const ClockEstimate& e) {
  char drift[96];
  std::snprintf(drift, sizeof drift, "drift %+.5f +- %.5f s/s", e.drift, e.drift_std);
  return "offset " + fmt(e.start) + " +- " + fmt(e.start_std).substr(1) + " s at the start, " + fmt(e.end) + " +- " +
         fmt(e.end_std).substr(1) + " s at the end (" + drift + ")";
}

}  // namespace

AuxiliaryTable read_auxiliary_csv(const AuxiliarySourceSpec& spec, const std::filesystem::path& file) {
  const std::string text = input::read_input_file(file, "auxiliary source '" + spec.name + "'", kMaxAuxiliaryFileBytes);
  const std::string where = file.string();
  AuxiliaryCsvParser parser(spec, where);
  AuxiliaryTable t;
  t.values.resize(spec.channels.size());
  for (std::size_t pos = 0; pos < text.size();) {
    const std::size_t nl = text.find('\n', pos);
    const std::string_view line = std::string_view(text).substr(pos, nl == std::string::npos ? std::string::npos : nl - pos);
    pos = nl == std::string::npos ? text.size() : nl + 1;
    const auto row = parser.line(line);
    if (!row) continue;
    t.time.push_back(row->time);
    for (std::size_t j = 0; j < row->values.size(); ++j) t.values[j].push_back(row->values[j]);
  }
  if (!parser.has_header()) throw InputError(where + ": auxiliary source '" + spec.name + "': empty file (no header line)");
  if (t.time.size() < 2) throw InputError(where + ": auxiliary source '" + spec.name + "': fewer than 2 rows of data");
  if (parser.repeated() > 0)
    t.warnings.push_back(where + ": " + std::to_string(parser.repeated()) + " rows repeating the previous row's time dropped");
  if (parser.non_finite() > 0)
    t.warnings.push_back(where + ": " + std::to_string(parser.non_finite()) + " non-finite values (nan, inf) left out");
  t.unmapped_columns = parser.unmapped_columns();
  return t;
}

std::string SourceReport::describe() const {
  if (file.empty()) return "source '" + name + "': not given for this run (--source " + name + "=FILE): left out";
  std::string s = "source '" + name + "' (" + file.filename().string() + "): " +
                  (followed ? "followed as it is written" : std::to_string(samples) + " samples") +
                  (unmapped_columns.empty() ? "" : " (columns not mapped: " + unmapped_columns + ")") +
                  ", clock offset " + fmt(offset) + " s";
  if (estimate)
    s += " +- " + fmt(estimate->std).substr(1) + " s (bus time = source time + offset; estimated, peak correlation " +
         fmt(estimate->correlation, 2).substr(1) + " at " + fmt(estimate->whole_run) + " s over the whole run, median of " +
         std::to_string(estimate->pieces) + " pieces; " + drift_text(*estimate) + ")";
  else
    s += " (fixed in the profile)";
  return s;
}

namespace {

std::size_t bus_channel(const VehicleProfile& p, const std::string& name) {
  for (std::size_t c = 0; c < p.channels.size(); ++c)
    if (p.channels[c].channel == name && !p.channels[c].source) return c;
  throw InputError("no bus channel '" + name + "'");
}

// The bus channels the estimates need, decoded from the whole log (one pass).
std::map<std::size_t, TimeSeries> bus_series(const VehicleProfile& p, FrameSource& bus, const std::set<std::size_t>& wanted) {
  std::map<std::size_t, TimeSeries> out;
  SignalMapper mapper(p);
  std::vector<ChannelSample> samples;
  can::Frame frame;
  while (bus.next(frame, std::chrono::milliseconds(0)) == NextStatus::Frame) {
    samples.clear();
    mapper.map(frame, samples);
    for (const auto& s : samples) {
      if (!wanted.count(s.channel)) continue;
      TimeSeries& ts = out[s.channel];
      if (!ts.t.empty() && !(s.time > ts.t.back())) continue;  // out of order, as the resampler drops it
      ts.t.push_back(s.time);
      ts.v.push_back(s.value);
    }
  }
  return out;
}

ChannelMapping source_mapping(const AuxiliarySourceSpec& spec, std::size_t si, std::size_t ci) {
  const SourceChannel& c = spec.channels[ci];
  ChannelMapping m;
  m.channel = c.channel;
  m.unit = c.unit;
  m.message = spec.name + "." + c.column;
  m.max_gap = c.max_gap;
  m.interpolation = c.interpolation;
  m.gain = c.gain;
  m.source = si;
  m.source_channel = ci;
  return m;
}

}  // namespace

namespace {

// The channel group of `file` holding channel `name` (not as its master): {data group, channel
// group}; InputError naming the file's groups when none or several hold it.
std::pair<std::size_t, std::size_t> group_of(const can::Mdf4File& file, const std::string& name,
                                             const std::string& where) {
  std::vector<std::pair<std::size_t, std::size_t>> found;
  std::string groups;
  for (std::size_t dg = 0; dg < file.data_groups().size(); ++dg)
    for (std::size_t cg = 0; cg < file.data_groups()[dg].groups.size(); ++cg) {
      const can::Mdf4ChannelGroup& g = file.data_groups()[dg].groups[cg];
      groups += (groups.empty() ? "'" : ", '") + g.name + "'";
      if (const can::Mdf4Channel* c = g.find(name); c != nullptr && !c->is_master())
        found.emplace_back(dg, cg);
    }
  if (found.size() == 1) return found.front();
  throw InputError(where + ": " +
                   (found.empty() ? "no channel '" + name + "' in the file"
                                  : "channel '" + name + "' is in " + std::to_string(found.size()) +
                                        " channel groups: which one is meant cannot be told") +
                   " (its channel groups: " + (groups.empty() ? "none" : groups) + ")");
}

// An MDF4 file of physical channels (CANape, INCA, asammdf): each source channel is the file's
// channel named by its `column`, at its channel group's master time after the header's start (s
// since 1970, the clock of MDF4 and candump bus logs), from the profile's unit to SI.
std::vector<TimeSeries> read_mdf4_source(const AuxiliarySourceSpec& spec, SourceReport& report) {
  const can::Mdf4File file(report.file);
  const std::string where = report.file.string() + ": source '" + spec.name + "'";
  const double start = static_cast<double>(file.start_ns()) / 1e9;
  std::vector<TimeSeries> series(spec.channels.size());
  std::uint64_t dropped = 0;
  for (std::size_t ci = 0; ci < spec.channels.size(); ++ci) {
    const std::string& name = spec.channels[ci].column;
    const auto [dg, cg] = group_of(file, name, where);
    const can::Mdf4Channel& channel = *file.data_groups()[dg].groups[cg].find(name);
    if (!channel.unit.empty() && channel.unit != spec.channels[ci].given_unit)
      report.warnings.push_back("channel '" + name + "': the file says '" + channel.unit +
                                "', the profile '" + spec.channels[ci].given_unit +
                                "': the profile's unit is used");
    const can::Mdf4Signals s = file.read_signals(dg, cg, {name});
    TimeSeries& ts = series[ci];
    for (std::size_t k = 0; k < s.time.size(); ++k) {
      const double t = start + s.time[k], v = s.values[0][k];
      if (!std::isfinite(v) || !std::isfinite(t) || (!ts.t.empty() && !(t > ts.t.back()))) {
        ++dropped;
        continue;
      }
      ts.t.push_back(t);
      ts.v.push_back(auxiliary_si(spec, ci, v));
    }
  }
  for (const std::string& note : file.notes()) report.warnings.push_back(note);
  if (dropped > 0)
    report.warnings.push_back(
        std::to_string(dropped) +
        " samples not finite or not after their channel's previous one dropped");
  return series;
}

// The source's channels as series on its own clock, in SI: a CSV file's columns, an MDF4 file's
// channels, or the channels a second bus's log gives through its DBC.
std::vector<TimeSeries> read_source(const AuxiliarySourceSpec& spec, SourceReport& report) {
  if (spec.type == "mdf4") return read_mdf4_source(spec, report);
  std::vector<TimeSeries> series(spec.channels.size());
  if (spec.type == "csv") {
    const AuxiliaryTable table = read_auxiliary_csv(spec, report.file);
    report.warnings = table.warnings;
    report.unmapped_columns = table.unmapped_columns;
    for (std::size_t ci = 0; ci < spec.channels.size(); ++ci)
      for (std::size_t i = 0; i < table.time.size(); ++i) {
        const double v = table.values[ci][i];
        if (!std::isfinite(v)) continue;
        series[ci].t.push_back(table.time[i]);
        series[ci].v.push_back(auxiliary_si(spec, ci, v));
      }
    return series;
  }
  LogSource log(report.file);
  SignalMapper mapper(*spec.bus);
  std::vector<ChannelSample> samples;
  can::Frame frame;
  std::uint64_t out_of_order = 0;
  while (log.next(frame, std::chrono::milliseconds(0)) == NextStatus::Frame) {
    samples.clear();
    mapper.map(frame, samples);
    for (const auto& x : samples) {
      TimeSeries& ts = series[x.channel];
      if (!ts.t.empty() && !(x.time > ts.t.back())) {
        ++out_of_order;
        continue;
      }
      ts.t.push_back(x.time);
      ts.v.push_back(x.value);
    }
  }
  if (mapper.stats().mapped == 0)
    throw InputError(report.file.string() + ": source '" + spec.name + "': none of its " +
                     std::to_string(mapper.stats().frames) + " frames gives a channel of the source (" +
                     std::to_string(log.bad_input()) + " bad lines or objects)");
  if (log.bad_input() > 0)
    report.warnings.push_back(std::to_string(log.bad_input()) + " bad lines or objects skipped; first: " + log.errors().front());
  if (out_of_order > 0)
    report.warnings.push_back(std::to_string(out_of_order) + " samples not after their channel's previous one dropped");
  return series;
}

}  // namespace

RunSources prepare_sources(const VehicleProfile& declared, const std::map<std::string, std::filesystem::path>& given,
                           FrameSource* bus, bool live, const LiveCanOpener& open_can) {
  for (const auto& [name, path] : given) {
    bool known = false;
    std::string names;
    for (const auto& s : declared.sources) known = known || s.name == name, names += (names.empty() ? "" : ", ") + s.name;
    if (!known)
      throw InputError("--source " + input::printable(name) + "=" + path.string() + ": the profile " +
                       declared.source.filename().string() + " declares no source '" + input::printable(name) +
                       "' (declared: " + (names.empty() ? "none" : names) + ")");
  }
  RunSources run{declared, {}, {}, {}};
  std::vector<std::vector<TimeSeries>> series(declared.sources.size());
  std::set<std::size_t> wanted;
  for (std::size_t si = 0; si < declared.sources.size(); ++si) {
    const AuxiliarySourceSpec& spec = declared.sources[si];
    SourceReport report;
    report.name = spec.name;
    const auto it = given.find(spec.name);
    report.file = it != given.end() ? it->second : spec.file;
    if (!report.file.empty()) {
      if (live && spec.type == "mdf4")
        throw InputError("source '" + spec.name + "' (" + report.file.string() +
                         "): an MDF4 file is read whole in "
                         "a replay; a live run follows CSV files and CAN interfaces");
      if (live && spec.type != "csv" && !open_can)
        throw InputError("source '" + spec.name + "' (" + report.file.string() + "): a second CAN bus is read live "
                         "only by dynid-car (its interface), else from its log in a replay");
      if (!live) series[si] = read_source(spec, report);
      if (spec.clock.offset) {
        report.offset = *spec.clock.offset;
      } else {
        if (bus == nullptr)
          throw InputError("source '" + spec.name + "': its clock offset is estimated from the replayed log; a live run "
                           "has none before it starts: give clock = { offset = <seconds> } in the profile");
        wanted.insert(bus_channel(declared, spec.clock.reference));
      }
      // Its channels: in place of the bus channels they replace, else after the bus channels.
      for (std::size_t ci = 0; ci < spec.channels.size(); ++ci) {
        ChannelMapping m = source_mapping(spec, si, ci);
        if (spec.channels[ci].replaces_bus) run.profile.channels[bus_channel(run.profile, m.channel)] = std::move(m);
        else run.profile.channels.push_back(std::move(m));
      }
    }
    run.reports.push_back(std::move(report));
  }
  std::map<std::size_t, TimeSeries> reference;
  if (!wanted.empty()) reference = bus_series(declared, *bus, wanted);
  for (std::size_t si = 0; si < declared.sources.size(); ++si) {
    const AuxiliarySourceSpec& spec = declared.sources[si];
    SourceReport& report = run.reports[si];
    if (report.file.empty()) continue;
    if (!spec.clock.offset) {
      std::size_t from = 0;
      while (spec.channels[from].channel != spec.clock.estimate_from) ++from;
      ClockOffsetOptions o;
      o.max_offset = spec.clock.max_offset;
      o.reference_derivative = spec.clock.reference_derivative;
      const std::string what = "source '" + spec.name + "' (" + report.file.string() + "): clock from " +
                               spec.clock.estimate_from + " against the bus's " + spec.clock.reference +
                               (o.reference_derivative ? " (its derivative)" : "");
      const ClockEstimate e =
          estimate_clock_offset(reference[bus_channel(declared, spec.clock.reference)], series[si][from], o, what);
      if (e.drifting())
        throw InputError(what + ": the clock drifts: " + drift_text(e) +
                         ": one offset cannot align it; put the source on the bus's clock first, "
                         "or give clock = { offset = ... } to accept it");
      report.estimate = e;
      report.offset = e.offset;
    }
    std::vector<std::size_t> column_of(spec.channels.size());
    for (std::size_t c = 0; c < run.profile.channels.size(); ++c)
      if (run.profile.channels[c].source == si) column_of[run.profile.channels[c].source_channel] = c;
    if (live) {
      report.followed = true;
      std::unique_ptr<LiveSource> follower;
      if (spec.type == "csv") follower = std::make_unique<AuxiliaryFollower>(spec, report.file, report.offset);
      else follower = open_can(spec, report.file.string(), report.offset);
      run.followed.push_back({std::move(follower), column_of, spec.wait});
      continue;
    }
    for (std::size_t ci = 0; ci < spec.channels.size(); ++ci)
      for (std::size_t i = 0; i < series[si][ci].t.size(); ++i) {
        run.samples.push_back({series[si][ci].t[i] + report.offset, column_of[ci], series[si][ci].v[i]});
        ++report.samples;
      }
  }
  std::stable_sort(run.samples.begin(), run.samples.end(),
                   [](const AuxiliarySample& a, const AuxiliarySample& b) { return a.time < b.time; });
  return run;
}

}  // namespace dynid::car
