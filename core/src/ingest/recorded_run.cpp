#include "dynid/ingest/recorded_run.hpp"

#include <algorithm>
#include <string>

#include "derived_channels.hpp"
#include "dynid/cancellation.hpp"
#include "dynid/error.hpp"
#include "dynid/signal/butterworth.hpp"
#include "dynid/signal/derivative.hpp"
#include "dynid/signal/zero_phase_filter.hpp"

namespace dynid::ingest {
namespace {

std::string chunk_name(const Chunk& c) {
  return "chunk " + c.vehicle + "/" + c.run + "#" + std::to_string(c.sequence);
}

bool passes_through(const RunAnnouncement& a, const std::string& channel) {
  const auto& pass = a.preprocessing.unfiltered;
  return std::find(pass.begin(), pass.end(), channel) != pass.end();
}

// One valid stretch [first, first + length) of the record, filtered and differentiated whole.
PreprocessedSegment preprocess_segment(const RecordedRun& run, const signal::Sos& sos,
                                       Eigen::Index first, Eigen::Index length) {
  const RunAnnouncement& a = run.announcement;
  const double period = 1.0 / a.sample_rate_hz;
  PreprocessedSegment out{static_cast<Eigen::Index>(run.first_sample_index) + first,
                          model::ChannelSet(period, length)};
  for (std::size_t j = 0; j < a.channels.size(); ++j) {
    const Eigen::VectorXd raw = run.samples.block(first, static_cast<Eigen::Index>(j), length, 1);
    Eigen::VectorXd values = raw;
    if (!passes_through(a, a.channels[j].name))
      values = signal::zero_phase_filter(sos, Eigen::MatrixXd(raw)).col(0);
    out.channels.add(a.channels[j].name, a.channels[j].unit, std::move(values));
  }
  for (const ChannelSpec& c : a.channels) {
    const std::string name = "d_" + c.name;
    if (out.channels.has(name)) continue;
    const Eigen::MatrixXd d = signal::derivative(Eigen::MatrixXd(out.channels[c.name]), period);
    out.channels.add(name, detail::derivative_unit(c.unit), d.col(0));
  }
  return out;
}

}  // namespace

RecordedRun assemble_run(RunAnnouncement announcement, const std::vector<Chunk>& chunks,
                         const ChunkLimits& limits) {
  announcement.validate();
  RecordedRun run{std::move(announcement), 0, {}, {}};
  if (chunks.empty())
    throw InputError("run " + run.announcement.vehicle + "/" + run.announcement.run +
                     ": no chunk stored");
  Eigen::Index rows = 0;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const Chunk& c = chunks[i];
    validate_chunk(c, run.announcement, limits);
    if (c.sequence != i)
      throw InputError(chunk_name(c) + ": expected sequence " + std::to_string(i));
    const std::uint64_t expected = chunks.front().first_sample_index + static_cast<std::uint64_t>(rows);
    if (i > 0 && c.first_sample_index != expected)
      throw InputError(chunk_name(c) + ": first sample " + std::to_string(c.first_sample_index) +
                       ", expected " + std::to_string(expected) + " (chunks must be contiguous)");
    rows += c.samples.rows();
  }
  run.first_sample_index = chunks.front().first_sample_index;
  run.samples.resize(rows, static_cast<Eigen::Index>(run.announcement.channels.size()));
  run.valid.reserve(static_cast<std::size_t>(rows));
  Eigen::Index at = 0;
  for (const Chunk& c : chunks) {
    run.samples.middleRows(at, c.samples.rows()) = c.samples;
    run.valid.insert(run.valid.end(), c.valid.begin(), c.valid.end());
    at += c.samples.rows();
  }
  return run;
}

std::vector<PreprocessedSegment> preprocess_offline(const RecordedRun& run) {
  const RunAnnouncement& a = run.announcement;
  const signal::Sos sos = signal::butterworth_lowpass(
      a.preprocessing.butterworth_order, a.preprocessing.cutoff(a.sample_rate_hz), a.sample_rate_hz);
  const Eigen::Index padlen = signal::zero_phase_padlen(sos);
  const Eigen::Index edge = a.preprocessing.edge_samples(a.sample_rate_hz);
  const auto n = static_cast<Eigen::Index>(run.valid.size());
  std::vector<PreprocessedSegment> out;
  for (Eigen::Index s = 0; s < n;) {
    if (run.valid[static_cast<std::size_t>(s)] == 0) {
      ++s;
      continue;
    }
    Eigen::Index e = s;
    while (e < n && run.valid[static_cast<std::size_t>(e)] != 0) ++e;
    if (e - s > padlen) {
      cancellation_point();
      out.push_back(preprocess_segment(run, sos, s, e - s));
      out.back().edge = edge;
    }
    s = e;
  }
  return out;
}

std::vector<PreprocessedSegment> preprocess_channel_again(const RecordedRun& run,
                                                          std::vector<PreprocessedSegment> segments,
                                                          Eigen::Index column) {
  return preprocess_channel_again(run, std::move(segments), column, run.samples.col(column));
}

std::vector<PreprocessedSegment> preprocess_channel_again(const RecordedRun& run,
                                                          std::vector<PreprocessedSegment> segments,
                                                          Eigen::Index column,
                                                          const Eigen::VectorXd& values) {
  const ChannelSpec& changed = run.announcement.channels.at(static_cast<std::size_t>(column));
  if (values.size() != run.samples.rows())
    throw InputError("preprocessing channel '" + changed.name +
                     "' again: " + std::to_string(values.size()) + " samples, the run has " +
                     std::to_string(run.samples.rows()));
  RecordedRun one{run.announcement, run.first_sample_index, values, run.valid};
  one.announcement.channels = {changed};
  const std::vector<PreprocessedSegment> again = preprocess_offline(one);
  if (again.size() != segments.size()) {  // not the same validity
    RecordedRun whole = run;
    whole.samples.col(column) = values;
    return preprocess_offline(whole);
  }
  // The derivative made from the channel, unless the run announces a channel of that name (which
  // preprocessing keeps as it is).
  const std::string derivative = "d_" + changed.name;
  const bool derived = std::none_of(run.announcement.channels.begin(), run.announcement.channels.end(),
                                    [&](const ChannelSpec& c) { return c.name == derivative; });
  for (std::size_t s = 0; s < segments.size(); ++s) {
    segments[s].channels.replace(changed.name, again[s].channels[changed.name]);
    if (derived) segments[s].channels.replace(derivative, again[s].channels[derivative]);
  }
  return segments;
}

}  // namespace dynid::ingest
