#include "dynid/ingest/run_processor.hpp"

#include <algorithm>
#include <limits>
#include <set>

#include "byte_codec.hpp"
#include "derived_channels.hpp"
#include "dynid/error.hpp"
#include "dynid/ingest/model_channels.hpp"
#include "dynid/model/channel_set.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/signal/butterworth.hpp"
#include "segment_stream.hpp"

namespace dynid::ingest {
namespace {

constexpr std::string_view kMagic = "DYNIDRPC";
constexpr std::uint16_t kVersion = 2;  // 2: rows outside the edge reach, the five-point derivative

struct ModelRun {
  ModelSpec spec;
  std::unique_ptr<model::Model> model;  // null when the run lacks its channels
  std::vector<model::ParameterInfo> parameters;
  std::vector<std::string> group_names;
  std::optional<ls::EquationGroups> groups;
  std::string note;
};

// Rows of one model built on one ready window: only at its new samples (not context, not
// look-ahead) on the decimation grid, so every row is folded.
struct FoldJob {
  std::size_t model;
  std::vector<model::GroupRows> rows;
};

// The checksum of the announcement's encoding (its trailer). Not the CRC of the whole encoding:
// a CRC over data followed by its own CRC is the same constant for every input.
std::uint32_t announcement_checksum(const RunAnnouncement& a) {
  const std::string bytes = encode_announcement(a);
  return detail::crc32_of(std::string_view(bytes).substr(0, bytes.size() - sizeof(std::uint32_t)));
}

bool announced(const RunAnnouncement& a, const std::string& name) {
  return std::any_of(a.channels.begin(), a.channels.end(),
                     [&](const ChannelSpec& c) { return c.name == name; });
}

}  // namespace

struct RunProcessor::Impl {
  Impl(RunAnnouncement a, ChunkLimits l);

  RunAnnouncement announcement;
  ChunkLimits limits;
  signal::Sos sos;
  double period;
  std::uint32_t announcement_crc = 0;
  std::vector<std::unique_ptr<model::Model>> built;          // models, before sorting out which run
  std::vector<std::pair<std::string, std::string>> derived;  // name, unit
  detail::Layout layout;
  std::vector<ModelRun> models;
  model::RowReach reach;
  Eigen::Index edge = 0;  // no row this near a segment's ends (Preprocessing::edge_samples)
  std::optional<detail::SegmentStream> segment;
  RunCounters counters;
  std::uint64_t next_sequence = 0;
  std::uint64_t next_index = 0;
  bool finished = false;

  void plan_derived();
  void plan_layout();
  void plan_models();
  model::ChannelSet channel_set(const Eigen::Ref<const Eigen::MatrixXd>& rows) const;
  void collect(detail::SegmentStream& seg, bool at_end, RunCounters& c,
               std::vector<FoldJob>& jobs) const;
  void end_segment(detail::SegmentStream& seg, RunCounters& c, std::vector<FoldJob>& jobs) const;
  void fold(const std::vector<FoldJob>& jobs);
  /// Runs step(*segment); when it throws, puts the segment back as it was (strong guarantee).
  template <class Step>
  void guarded(Step&& step);
  /// RunProcessor::push; `validated`: validate_chunk passed for this announcement and limits.
  void push(const Chunk& chunk, bool validated);
};

RunProcessor::Impl::Impl(RunAnnouncement a, ChunkLimits l)
    : announcement((a.validate(), std::move(a))),
      limits(l),
      sos(signal::butterworth_lowpass(
          announcement.preprocessing.butterworth_order,
          announcement.preprocessing.cutoff(announcement.sample_rate_hz),
          announcement.sample_rate_hz)),
      period(1.0 / announcement.sample_rate_hz),
      announcement_crc(announcement_checksum(announcement)) {
  for (const ModelSpec& spec : announcement.models)
    built.push_back(model::make_model(spec.model, spec.constants));
  plan_derived();
  plan_layout();
  // Every row gets the context and look-ahead its model reads (e.g. a clutch mask over the
  // filter's window), so it is the row of a whole-segment call whatever the chunking.
  for (const auto& m : built) {
    const model::RowReach r = m->reach(period);
    reach.back = std::max(reach.back, r.back);
    reach.ahead = std::max(reach.ahead, r.ahead);
  }
  // A row is built once `edge` later samples of its segment are in (or the segment ended): only
  // then is it known not to lie within the filter's edge reach of the segment's end.
  edge = announcement.preprocessing.edge_samples(announcement.sample_rate_hz);
  reach.ahead = std::max(reach.ahead, edge);
  segment.emplace(sos, layout, period, announcement.preprocessing.filter_tolerance, reach);
  plan_models();
}

void RunProcessor::Impl::plan_derived() {
  // d_<name> is made here when a model reads it, the run does not measure it and has <name>.
  std::set<std::string> seen;
  for (std::size_t i = 0; i < built.size(); ++i)
    for (const std::string& c : channels_read(*built[i], announcement.models[i])) {
      if (c.rfind("d_", 0) != 0 || announced(announcement, c) || !seen.insert(c).second) continue;
      const std::string base = c.substr(2);
      if (!announced(announcement, base)) continue;
      const std::size_t col = announcement.column_of(base);
      derived.emplace_back(c, detail::derivative_unit(announcement.channels[col].unit));
      layout.derived_from.push_back(static_cast<Eigen::Index>(col));
    }
}

void RunProcessor::Impl::plan_layout() {
  const std::vector<std::string>& pass = announcement.preprocessing.unfiltered;
  layout.announced = static_cast<Eigen::Index>(announcement.channels.size());
  for (Eigen::Index j = 0; j < layout.announced; ++j) {
    const std::string& name = announcement.channels[static_cast<std::size_t>(j)].name;
    const bool through = std::find(pass.begin(), pass.end(), name) != pass.end();
    (through ? layout.unfiltered : layout.filtered).push_back(j);
  }
  if (layout.filtered.empty())
    throw InputError("run announcement " + announcement.vehicle + "/" + announcement.run +
                     ": every channel is listed as unfiltered; nothing to low-pass");
}

void RunProcessor::Impl::plan_models() {
  // An empty set with every channel the run will have: checks units and effects up front.
  const model::ChannelSet probe = channel_set(Eigen::MatrixXd(0, layout.width()));
  for (std::size_t i = 0; i < built.size(); ++i) {
    ModelRun run;
    run.spec = announcement.models[i];
    run.group_names = built[i]->groups();
    run.parameters = built[i]->parameters_with(run.spec.effects);
    const ChannelGaps gaps =
        channel_gaps(*built[i], run.spec, [&](const std::string& c) { return probe.has(c); });
    if (!gaps.missing.empty()) {
      run.note = "not run: the run has no channel " + quoted_list(gaps.missing);
    } else {
      (void)built[i]->rows(probe, run.spec.effects);  // throws on a wrong unit or effect
      run.groups.emplace(static_cast<Eigen::Index>(run.parameters.size()), run.group_names);
      run.model = std::move(built[i]);
    }
    models.push_back(std::move(run));
  }
  built.clear();
}

model::ChannelSet RunProcessor::Impl::channel_set(
    const Eigen::Ref<const Eigen::MatrixXd>& rows) const {
  model::ChannelSet set(period, rows.rows());
  for (std::size_t j = 0; j < announcement.channels.size(); ++j)
    set.add(announcement.channels[j].name, announcement.channels[j].unit,
            rows.col(static_cast<Eigen::Index>(j)));
  for (std::size_t j = 0; j < derived.size(); ++j)
    set.add(derived[j].first, derived[j].second,
            rows.col(layout.announced + static_cast<Eigen::Index>(j)));
  return set;
}

void RunProcessor::Impl::collect(detail::SegmentStream& seg, bool at_end, RunCounters& c,
                                 std::vector<FoldJob>& jobs) const {
  const auto decimation = static_cast<std::uint64_t>(announcement.preprocessing.odmf);
  const detail::ReadyRows ready = seg.ready(at_end);
  if (ready.new_count == 0) return;
  // The samples of the context (already folded) and of the look-ahead (not final) are left
  // out, and so are those off the decimation grid: the run's grid index decides, not where a
  // chunk or a filter block begins; and those within the filter's edge reach of the segment's
  // ends (before the end, ready() holds back reach.ahead >= edge samples). Rows are built at the
  // kept samples only, as ingest::row_at() keeps them offline.
  std::vector<Eigen::Index> grid;
  const std::uint64_t first = seg.start_index() + static_cast<std::uint64_t>(ready.first_index);
  const Eigen::Index last = at_end ? seg.length() - edge : std::numeric_limits<Eigen::Index>::max();
  for (Eigen::Index k = ready.first_new; k < ready.first_new + ready.new_count; ++k) {
    const Eigen::Index in_segment = ready.first_index + k;
    if ((first + static_cast<std::uint64_t>(k)) % decimation == 0 && in_segment >= edge && in_segment < last)
      grid.push_back(k);
  }
  if (!grid.empty()) {
    const model::ChannelSet set = channel_set(ready.rows);
    for (std::size_t m = 0; m < models.size(); ++m)
      if (models[m].model)
        jobs.push_back({m, models[m].model->rows_at(set, grid, models[m].spec.effects)});
  }
  c.final_samples += static_cast<std::uint64_t>(ready.new_count);
  seg.consume(ready.new_count);
}

void RunProcessor::Impl::end_segment(detail::SegmentStream& seg, RunCounters& c,
                                     std::vector<FoldJob>& jobs) const {
  if (!seg.active()) return;
  if (seg.long_enough()) {
    seg.finish();
    collect(seg, true, c, jobs);
    ++c.segments;
  } else {
    ++c.short_segments;
    c.short_segment_samples += static_cast<std::uint64_t>(seg.length());
  }
  seg.stop();
}

void RunProcessor::Impl::fold(const std::vector<FoldJob>& jobs) {
  for (const FoldJob& job : jobs)
    for (std::size_t g = 0; g < job.rows.size(); ++g)
      if (job.rows[g].W.rows() > 0) models[job.model].groups->fold(g, job.rows[g].W, job.rows[g].y);
}

template <class Step>
void RunProcessor::Impl::guarded(Step&& step) {
  // The segment is worked on in place under a mark, not on a copy: a copy of its held rows
  // would cost their memory (~80 KB for 30 channels) and a copy per push.
  segment->mark();
  try {
    step(*segment);
  } catch (...) {
    segment->rollback();
    throw;
  }
  segment->commit();
}

RunProcessor::RunProcessor(RunAnnouncement announcement, ChunkLimits limits)
    : impl_(std::make_unique<Impl>(std::move(announcement), limits)) {}
RunProcessor::RunProcessor(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RunProcessor::~RunProcessor() = default;
RunProcessor::RunProcessor(RunProcessor&&) noexcept = default;
RunProcessor& RunProcessor::operator=(RunProcessor&&) noexcept = default;

void RunProcessor::push(const Chunk& chunk) {
  impl_->push(chunk, false);
}

void RunProcessor::push(const ValidatedChunk& chunk) {
  impl_->push(chunk.chunk(), chunk.validated_for(impl_->announcement, impl_->limits));
}

void RunProcessor::Impl::push(const Chunk& chunk, bool validated) {
  const std::string where =
      "chunk " + chunk.vehicle + "/" + chunk.run + "#" + std::to_string(chunk.sequence) + ": ";
  if (finished) throw InputError(where + "the run is finished");
  if (!validated) validate_chunk(chunk, announcement, limits);
  if (chunk.sequence != next_sequence)
    throw InputError(where + "out of order, expected sequence " + std::to_string(next_sequence));
  if (counters.chunks > 0 && chunk.first_sample_index != next_index)
    throw InputError(where + "starts at sample " + std::to_string(chunk.first_sample_index) +
                     ", expected " + std::to_string(next_index) +
                     " (gaps are sent as invalid rows, not skipped)");
  // Counters are updated on a copy: a model rejecting the data leaves everything unchanged.
  RunCounters c = counters;
  const Eigen::Index m = chunk.samples.rows();
  guarded([&](detail::SegmentStream& seg) {
    std::vector<FoldJob> jobs;
    for (Eigen::Index k = 0; k < m;) {
      const std::uint8_t flag = chunk.valid[static_cast<std::size_t>(k)];
      Eigen::Index e = k;
      while (e < m && chunk.valid[static_cast<std::size_t>(e)] == flag) ++e;
      if (flag == 1) {
        if (!seg.active()) seg.start(chunk.first_sample_index + static_cast<std::uint64_t>(k));
        seg.push(chunk.samples.middleRows(k, e - k));
        collect(seg, false, c, jobs);
      } else {
        end_segment(seg, c, jobs);
        c.invalid_samples += static_cast<std::uint64_t>(e - k);
      }
      k = e;
    }
    fold(jobs);
  });
  counters = c;
  ++counters.chunks;
  counters.samples += static_cast<std::uint64_t>(m);
  ++next_sequence;
  next_index = chunk.first_sample_index + static_cast<std::uint64_t>(m);
}

void RunProcessor::finish() {
  Impl& s = *impl_;
  if (s.finished)
    throw InputError("run " + s.announcement.vehicle + "/" + s.announcement.run +
                     ": already finished");
  RunCounters c = s.counters;
  s.guarded([&](detail::SegmentStream& seg) {
    std::vector<FoldJob> jobs;
    s.end_segment(seg, c, jobs);
    s.fold(jobs);
  });
  s.counters = c;
  s.finished = true;
}

std::vector<ModelEstimate> RunProcessor::estimates(const ls::EstimateOptions& options) const {
  std::vector<ModelEstimate> out;
  for (const ModelRun& m : impl_->models) {
    ModelEstimate e{m.spec.model, m.parameters, m.group_names, {}, std::nullopt, m.note};
    std::uint64_t total = 0;
    for (std::size_t g = 0; m.groups && g < m.groups->size(); ++g) {
      e.group_rows.push_back(m.groups->group(g).row_count());
      total += e.group_rows.back();
    }
    if (m.groups && total == 0) e.note = "no rows yet";
    if (total > 0) e.estimate = m.groups->estimate(options);
    out.push_back(std::move(e));
  }
  return out;
}

std::string RunProcessor::checkpoint() const {
  const Impl& s = *impl_;
  detail::ByteWriter w;
  w.bytes().append(kMagic);
  w.put<std::uint16_t>(kVersion);
  w.put<std::uint32_t>(s.announcement_crc);
  w.put<std::uint64_t>(s.next_sequence);
  w.put<std::uint64_t>(s.next_index);
  w.put_bool(s.finished);
  const RunCounters& c = s.counters;
  for (std::uint64_t v : {c.chunks, c.samples, c.invalid_samples, c.segments, c.short_segments,
                          c.short_segment_samples, c.final_samples})
    w.put<std::uint64_t>(v);
  s.segment->save(w);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(s.models.size()));
  for (const ModelRun& m : s.models) {
    w.put<std::uint32_t>(m.groups ? static_cast<std::uint32_t>(m.groups->size()) : 0);
    for (std::size_t g = 0; m.groups && g < m.groups->size(); ++g)
      w.put_bytes(m.groups->group(g).serialize());
  }
  w.seal();
  return w.take();
}

RunProcessor RunProcessor::restore(RunAnnouncement announcement, std::string_view bytes,
                                   ChunkLimits limits) {
  auto impl = std::make_unique<Impl>(std::move(announcement), limits);
  Impl& s = *impl;
  detail::ByteReader r(bytes, "run checkpoint");
  r.open(kMagic, kVersion);
  if (r.get<std::uint32_t>("announcement checksum") != s.announcement_crc)
    r.fail("it belongs to another announcement of " + s.announcement.vehicle + "/" +
           s.announcement.run);
  s.next_sequence = r.get<std::uint64_t>("next sequence");
  s.next_index = r.get<std::uint64_t>("next sample index");
  s.finished = r.get_bool("finished");
  RunCounters& c = s.counters;
  for (std::uint64_t* v : {&c.chunks, &c.samples, &c.invalid_samples, &c.segments,
                           &c.short_segments, &c.short_segment_samples, &c.final_samples})
    *v = r.get<std::uint64_t>("counters");
  s.segment->load(r);
  if (r.get<std::uint32_t>("model count") != s.models.size()) r.fail("model count differs");
  for (ModelRun& m : s.models) {
    const std::size_t groups = m.groups ? m.groups->size() : 0;
    if (r.get<std::uint32_t>("group count") != groups) r.fail("group count of " + m.spec.model);
    for (std::size_t g = 0; g < groups; ++g) {
      ls::Accumulator acc = ls::Accumulator::deserialize(r.get_bytes("accumulator"));
      if (acc.parameter_count() != m.groups->group(g).parameter_count())
        r.fail("accumulator of " + m.spec.model + " has the wrong parameter count");
      m.groups->group(g) = std::move(acc);
    }
  }
  r.expect_end();
  return RunProcessor(std::move(impl));
}

const RunAnnouncement& RunProcessor::announcement() const {
  return impl_->announcement;
}
std::size_t RunProcessor::model_count() const {
  return impl_->models.size();
}
const ls::EquationGroups* RunProcessor::groups(std::size_t model) const {
  const ModelRun& m = impl_->models.at(model);
  return m.groups ? &*m.groups : nullptr;
}
const RunCounters& RunProcessor::counters() const {
  return impl_->counters;
}
std::uint64_t RunProcessor::next_sequence() const {
  return impl_->next_sequence;
}
std::uint64_t RunProcessor::next_sample_index() const {
  return impl_->next_index;
}
bool RunProcessor::finished() const {
  return impl_->finished;
}
std::vector<std::pair<std::string, std::string>> RunProcessor::derived_channels() const {
  return impl_->derived;
}
std::vector<signal::HeldBuffer> RunProcessor::held_buffers() const {
  const Impl& s = *impl_;
  std::vector<signal::HeldBuffer> out;
  s.segment->held_buffers("segment ", out);
  for (const ModelRun& m : s.models) {
    std::size_t bytes = 0;
    for (std::size_t g = 0; m.groups && g < m.groups->size(); ++g) {
      const ls::Accumulator::ExtendedMatrix& r = m.groups->group(g).augmented_r_extended();
      bytes += static_cast<std::size_t>(r.size()) * sizeof(ls::Accumulator::Extended);
    }
    if (m.groups) out.push_back({m.spec.model + " accumulators", bytes, bytes});
  }
  return out;
}

const signal::Sos& RunProcessor::filter() const {
  return impl_->sos;
}

}  // namespace dynid::ingest
