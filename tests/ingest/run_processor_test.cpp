// RunProcessor: the result does not depend on the chunking, checkpoints restore exactly, gaps
// split the processing into segments, rejected chunks change nothing, and the streamed result
// matches the fully offline path (whole-segment filtfilt + derivative + batch fold).
#include "dynid/ingest/run_processor.hpp"

#include <cmath>
#include <cstdio>

#include "dynid/model/channel_set.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/signal/derivative.hpp"
#include "dynid/signal/streaming_zero_phase_filter.hpp"
#include "dynid/signal/zero_phase_filter.hpp"
#include "ingest_test_support.hpp"

namespace dynid::ingest {
namespace {

using test::TestRun;

// Feeds the run in chunks of the given sizes (from chunk `from` on) and finishes unless told.
void feed(RunProcessor& p, const TestRun& run, const std::vector<Eigen::Index>& sizes,
          std::size_t from = 0, std::size_t to = SIZE_MAX) {
  Eigen::Index first = 0;
  for (std::size_t i = 0; i < from; ++i) first += sizes[i];
  for (std::size_t i = from; i < std::min(to, sizes.size()); ++i) {
    p.push(test::cut(run, i, first, sizes[i]));
    first += sizes[i];
  }
}

RunProcessor processed(const TestRun& run, const std::vector<Eigen::Index>& sizes) {
  RunProcessor p(run.announcement);
  feed(p, run, sizes);
  p.finish();
  return p;
}

// Largest relative difference of values and standard deviations over every identified parameter.
double estimate_difference(const std::vector<ModelEstimate>& a,
                           const std::vector<ModelEstimate>& b) {
  double worst = 0.0;
  EXPECT_EQ(a.size(), b.size());
  for (std::size_t m = 0; m < a.size(); ++m) {
    EXPECT_EQ(a[m].estimate.has_value(), b[m].estimate.has_value()) << a[m].model;
    if (!a[m].estimate || !b[m].estimate) continue;
    const ls::Estimate& x = a[m].estimate->estimate;
    const ls::Estimate& y = b[m].estimate->estimate;
    EXPECT_EQ(x.rows, y.rows) << a[m].model;
    for (Eigen::Index j = 0; j < x.value.size(); ++j) {
      EXPECT_EQ(std::isfinite(x.value(j)), std::isfinite(y.value(j)));
      if (!std::isfinite(y.value(j))) continue;
      worst = std::max(worst, std::abs(x.value(j) - y.value(j)) / std::abs(y.value(j)));
      worst = std::max(worst, std::abs(x.standard_deviation(j) - y.standard_deviation(j)) /
                                  y.standard_deviation(j));
    }
  }
  return worst;
}

void expect_bit_identical(const RunProcessor& a, const RunProcessor& b) {
  ASSERT_EQ(a.model_count(), b.model_count());
  for (std::size_t m = 0; m < a.model_count(); ++m) {
    ASSERT_EQ(a.groups(m) == nullptr, b.groups(m) == nullptr);
    if (a.groups(m) == nullptr) continue;
    for (std::size_t g = 0; g < a.groups(m)->size(); ++g)
      EXPECT_EQ(a.groups(m)->group(g).serialize(), b.groups(m)->group(g).serialize())
          << "model " << m << " group " << g;
  }
}

const std::vector<ModelEstimate>& one_chunk_estimates() {
  static const std::vector<ModelEstimate> e = [] {
    const TestRun run = test::make_run();
    return processed(run, {run.samples.rows()}).estimates();
  }();
  return e;
}

TEST(RunProcessor, RecoversTheSimulatedParameters) {
  const std::vector<ModelEstimate>& e = one_chunk_estimates();
  const test::Truth t;
  ASSERT_EQ(e.size(), 3u);
  for (const ModelEstimate& m : e) ASSERT_TRUE(m.estimate.has_value()) << m.model << ": " << m.note;
  const Eigen::VectorXd lon = e[0].estimate->estimate.value;
  EXPECT_EQ(e[0].parameters[0].name, "mass");
  EXPECT_NEAR(lon(0), t.mass, 0.01 * t.mass);
  EXPECT_NEAR(lon(1), t.scx, 0.05 * t.scx);
  EXPECT_NEAR(lon(2), t.rolling, 0.1 * t.rolling);
  const Eigen::VectorXd kin = e[1].estimate->estimate.value;
  EXPECT_NEAR(kin(0), t.scale, 0.01);
  EXPECT_NEAR(kin(1), t.offset, 0.02);
  EXPECT_EQ(e[1].parameters.back().name, "dict:lag2:vx");
  EXPECT_NEAR(kin(2), 0.0, 0.01);  // nothing to explain
  const Eigen::VectorXd drv = e[2].estimate->estimate.value;
  EXPECT_NEAR(drv(0), t.inertia, 0.02 * t.inertia);
  EXPECT_NEAR(drv(1), t.p, 0.1 * t.p);
}

TEST(RunProcessor, RandomChunkingsGiveTheSameEstimates) {
  const TestRun run = test::make_run();
  const std::vector<ModelEstimate>& reference = one_chunk_estimates();
  for (const auto& [largest, seed] : {std::pair{Eigen::Index{3}, 1u},
                                      {Eigen::Index{40}, 2u},
                                      {Eigen::Index{333}, 3u},
                                      {Eigen::Index{2500}, 4u}}) {
    const RunProcessor p = processed(run, test::random_cuts(run.samples.rows(), largest, seed));
    const double diff = estimate_difference(p.estimates(), reference);
    EXPECT_LT(diff, 1e-12) << "chunks up to " << largest;
    std::printf("chunks up to %ld: max relative difference to one chunk %.2e\n",
                static_cast<long>(largest), diff);
  }
}

TEST(RunProcessor, CheckpointRestoreContinuesBitIdentically) {
  const TestRun run = test::make_run();
  const std::vector<Eigen::Index> sizes = test::random_cuts(run.samples.rows(), 150, 9u);
  const RunProcessor whole = processed(run, sizes);
  std::mt19937 rng(5u);
  std::uniform_int_distribution<std::size_t> at(0, sizes.size());
  for (int trial = 0; trial < 6; ++trial) {
    const std::size_t cut = trial == 0 ? 0 : trial == 1 ? sizes.size() : at(rng);
    RunProcessor first(run.announcement);
    feed(first, run, sizes, 0, cut);
    const std::string bytes = first.checkpoint();
    RunProcessor second = RunProcessor::restore(run.announcement, bytes);
    EXPECT_EQ(second.checkpoint(), bytes);
    EXPECT_EQ(second.next_sequence(), cut);
    feed(second, run, sizes, cut);
    second.finish();
    expect_bit_identical(second, whole);
    EXPECT_EQ(second.counters().final_samples, whole.counters().final_samples);
    EXPECT_EQ(second.checkpoint(), whole.checkpoint()) << "cut after chunk " << cut;
  }
}

TEST(RunProcessor, RestoreRejectsCorruptionAndAnotherAnnouncement) {
  const TestRun run = test::make_run(2000);
  RunProcessor p(run.announcement);
  feed(p, run, {700, 300});
  const std::string bytes = p.checkpoint();
  for (std::size_t i = 0; i < bytes.size(); i += 97) {
    std::string bad = bytes;
    bad[i] = static_cast<char>(bad[i] ^ 0x04);
    EXPECT_THROW((void)RunProcessor::restore(run.announcement, bad), InputError) << "byte " << i;
  }
  EXPECT_THROW((void)RunProcessor::restore(run.announcement, bytes.substr(0, 100)), InputError);
  RunAnnouncement other = run.announcement;
  other.preprocessing.odmf = 4;
  test::expect_input_error([&] { (void)RunProcessor::restore(other, bytes); },
                           {"another announcement"});
}

TEST(RunProcessor, GapsSplitTheRunIntoSegmentsAndGarbageInGapsDoesNotMatter) {
  const TestRun run = test::make_run();
  const RunProcessor p = processed(run, test::random_cuts(run.samples.rows(), 200, 11u));
  const RunCounters& c = p.counters();
  EXPECT_EQ(c.samples, 6000u);
  EXPECT_EQ(c.invalid_samples, 75u);
  EXPECT_EQ(c.segments, 3u);        // [0,1500), [1560,3000), [3025,6000)
  EXPECT_EQ(c.short_segments, 1u);  // [1540,1550): too short to filter
  EXPECT_EQ(c.short_segment_samples, 10u);
  EXPECT_EQ(c.final_samples, 6000u - 75u - 10u);
  TestRun clean = run;
  for (Eigen::Index k = 0; k < clean.samples.rows(); ++k)
    if (clean.valid[static_cast<std::size_t>(k)] == 0) clean.samples.row(k).setZero();
  expect_bit_identical(processed(clean, test::random_cuts(run.samples.rows(), 200, 11u)), p);
}

// The fully offline path: every valid segment long enough is filtered whole (zero_phase_filter,
// pass-through channels kept), differentiated whole, and its rows folded in one batch, those
// within the filter's edge reach of the segment's ends left out.
std::vector<ModelEstimate> offline_estimates(const TestRun& run, const RunProcessor& p) {
  const RunAnnouncement& a = run.announcement;
  const double period = 1.0 / a.sample_rate_hz;
  const Eigen::Index padlen = signal::zero_phase_padlen(p.filter());
  const Eigen::Index edge = signal::zero_phase_edge_reach(p.filter(), kEdgeOutsideShare);
  std::vector<std::unique_ptr<model::Model>> models;
  std::vector<ls::EquationGroups> groups;
  for (const ModelSpec& spec : a.models) {
    models.push_back(model::make_model(spec.model, spec.constants));
    groups.emplace_back(
        static_cast<Eigen::Index>(models.back()->parameters_with(spec.effects).size()),
        models.back()->groups());
  }
  const Eigen::Index n = run.samples.rows();
  for (Eigen::Index s = 0; s < n;) {
    if (run.valid[static_cast<std::size_t>(s)] == 0) {
      ++s;
      continue;
    }
    Eigen::Index e = s;
    while (e < n && run.valid[static_cast<std::size_t>(e)] == 1) ++e;
    const Eigen::Index len = e - s;
    if (len > padlen) {
      Eigen::MatrixXd x = run.samples.middleRows(s, len);
      for (Eigen::Index j = 0; j < x.cols(); ++j)
        if (a.channels[static_cast<std::size_t>(j)].name != "gear")
          x.col(j) = signal::zero_phase_filter(p.filter(), Eigen::MatrixXd(x.col(j)));
      model::ChannelSet set(period, len);
      for (std::size_t j = 0; j < a.channels.size(); ++j)
        set.add(a.channels[j].name, a.channels[j].unit, x.col(static_cast<Eigen::Index>(j)));
      for (const auto& [name, unit] : p.derived_channels()) {
        const Eigen::MatrixXd d = signal::derivative(set[name.substr(2)], period);
        set.add(name, unit, d.col(0));
      }
      for (std::size_t m = 0; m < models.size(); ++m) {
        const std::vector<model::GroupRows> rows = models[m]->rows(set, a.models[m].effects);
        // DYCARO's decimation: rows on the run's samples whose index is a multiple of odmf.
        for (std::size_t g = 0; g < rows.size(); ++g) {
          std::vector<Eigen::Index> keep;
          for (std::size_t i = 0; i < rows[g].samples.size(); ++i) {
            const Eigen::Index k = rows[g].samples[i];
            if ((s + k) % a.preprocessing.odmf == 0 && k >= edge && k < len - edge)
              keep.push_back(static_cast<Eigen::Index>(i));
          }
          if (!keep.empty()) groups[m].fold(g, rows[g].W(keep, Eigen::all), rows[g].y(keep));
        }
      }
    }
    s = e;
  }
  std::vector<ModelEstimate> out;
  for (std::size_t m = 0; m < models.size(); ++m)
    out.push_back({a.models[m].model, {}, {}, {}, groups[m].estimate(), ""});
  return out;
}

TEST(RunProcessor, MatchesTheFullyOfflinePathWithinTheFilterTolerance) {
  const TestRun run = test::make_run();
  const RunProcessor p = processed(run, test::random_cuts(run.samples.rows(), 100, 21u));
  const double diff = estimate_difference(p.estimates(), offline_estimates(run, p));
  std::printf("streamed vs fully offline (tolerance %.0e): max relative difference %.2e\n",
              run.announcement.preprocessing.filter_tolerance, diff);
  EXPECT_LT(diff, 1e-6);
  EXPECT_GT(diff, 0.0);  // the streamed backward pass is an approximation, bounded above
}

// Decimation (odmf 5 here) keeps the rows on the run's sample grid: the same rows as the
// offline path's selection, and a fifth of the rows of the same filter without decimation.
TEST(RunProcessor, DecimationKeepsTheRowsOnTheRunGrid) {
  const TestRun run = test::make_run();
  TestRun full = run;
  full.announcement.preprocessing.cutoff_hz = full.announcement.preprocessing.cutoff(100.0);
  full.announcement.preprocessing.odmf = 1;
  const RunProcessor p = processed(run, test::random_cuts(run.samples.rows(), 77, 4u));
  const RunProcessor q = processed(full, test::random_cuts(run.samples.rows(), 77, 4u));
  EXPECT_TRUE(p.filter().matrix() == q.filter().matrix());
  for (std::size_t m = 0; m < p.model_count(); ++m) {
    const double decimated = static_cast<double>(p.estimates()[m].group_rows.at(0));
    const double every = static_cast<double>(q.estimates()[m].group_rows.at(0));
    EXPECT_NEAR(decimated, every / 5.0, 4.0) << p.estimates()[m].model;  // +-1 per segment
  }
  test::expect_input_error(
      [&] {
        RunAnnouncement bad = full.announcement;
        bad.preprocessing.odmf = 0;
        RunProcessor r(bad);
      },
      {"odmf"});
}

// clutch_slip's mask reads 0.4 s around each row (model::Model::reach): every chunking gives the
// same rows (the same count, estimates to rounding) as one chunk and as the offline path, and a
// restore anywhere continues bit for bit. With only the least context (3 back, 1 ahead) the mask
// saw the stuck samples of the current window only, and the rows depended on the chunking.
TEST(RunProcessor, RowsThatReadFarAroundTheirSampleDoNotDependOnTheChunking) {
  const TestRun run = test::make_clutch_run();
  const RunProcessor one = processed(run, {run.samples.rows()});
  ASSERT_NE(one.groups(0), nullptr);
  // Enough rows that the comparisons below are not of an empty fit (268: the open rows near
  // the clutch closing are left out too, clutch_slip.hpp, and those within the filter's edge
  // reach of the run's ends).
  EXPECT_GT(one.groups(0)->group(0).row_count(), 250u);
  for (const auto& [largest, seed] : {std::pair{Eigen::Index{1}, 1u},
                                      {Eigen::Index{13}, 2u},
                                      {Eigen::Index{90}, 3u},
                                      {Eigen::Index{1000}, 4u}}) {
    const RunProcessor p = processed(run, test::random_cuts(run.samples.rows(), largest, seed));
    EXPECT_LT(estimate_difference(p.estimates(), one.estimates()), 1e-12) << "chunks up to " << largest;
  }
  const double offline = estimate_difference(one.estimates(), offline_estimates(run, one));
  EXPECT_LT(offline, 1e-6);
  const std::vector<Eigen::Index> sizes = test::random_cuts(run.samples.rows(), 60, 8u);
  const RunProcessor whole = processed(run, sizes);
  for (const std::size_t cut : {std::size_t{1}, sizes.size() / 3, sizes.size() / 2 + 1}) {
    RunProcessor first(run.announcement);
    feed(first, run, sizes, 0, cut);
    RunProcessor second = RunProcessor::restore(run.announcement, first.checkpoint());
    feed(second, run, sizes, cut);
    second.finish();
    expect_bit_identical(second, whole);
    EXPECT_EQ(second.checkpoint(), whole.checkpoint()) << "cut after chunk " << cut;
  }
}

TEST(RunProcessor, ARejectedChunkChangesNoState) {
  const TestRun run = test::make_run(3000);
  const std::vector<Eigen::Index> sizes = test::random_cuts(run.samples.rows(), 120, 3u);
  RunProcessor p(run.announcement);
  feed(p, run, sizes, 0, 10);
  const std::string before = p.checkpoint();
  Eigen::Index next = 0;
  for (std::size_t i = 0; i < 10; ++i) next += sizes[i];
  Chunk nan = test::cut(run, 10, next, sizes[10]);
  nan.samples(1, 2) = std::numeric_limits<double>::quiet_NaN();
  nan.seal();
  test::expect_input_error([&] { p.push(nan); }, {"#10", "'wheel_torque'", "NaN"});
  test::expect_input_error([&] { p.push(test::cut(run, 9, next - sizes[9], sizes[9])); },
                           {"out of order", "expected sequence 10"});  // a duplicate
  test::expect_input_error([&] { p.push(test::cut(run, 11, next, sizes[10])); },
                           {"expected sequence 10"});
  test::expect_input_error([&] { p.push(test::cut(run, 10, next + 1, sizes[10])); },
                           {"starts at sample", "expected " + std::to_string(next)});
  Chunk corrupt = test::cut(run, 10, next, sizes[10]);
  corrupt.samples(0, 0) += 1.0;
  EXPECT_THROW(p.push(corrupt), InputError);
  EXPECT_EQ(p.checkpoint(), before);
  feed(p, run, sizes, 10);
  p.finish();
  EXPECT_THROW(p.finish(), InputError);
  EXPECT_THROW(p.push(test::cut(run, sizes.size(), 0, 1)), InputError);
  expect_bit_identical(p, processed(run, sizes));
}

// A model rejecting a row in the middle of a chunk, after the filter has moved on (and, in the
// second case, after a gap ended the segment and a new one started in that chunk), leaves the
// processor as it was: the run then goes on as if the bad chunk had never come.
TEST(RunProcessor, AModelRejectingARowMidChunkChangesNoState) {
  const TestRun run = test::make_run(3000);
  ChunkLimits wide;
  wide.max_abs_value = 1e300;  // lets through an engine speed whose square overflows
  struct Case {
    Eigen::Index first, count, spike;  // the bad chunk, and where its spike starts
  };
  for (const Case c : {Case{600, 600, 650}, Case{1400, 700, 1700}}) {
    std::vector<Eigen::Index> sizes;  // chunks of 100 rows, but the bad one
    for (Eigen::Index at = 0; at < run.samples.rows(); at += sizes.back())
      sizes.push_back(at == c.first ? c.count
                                    : std::min<Eigen::Index>(100, run.samples.rows() - at));
    const std::size_t bad = static_cast<std::size_t>(c.first / 100);
    RunProcessor p(run.announcement, wide);
    feed(p, run, sizes, 0, bad);
    const std::string before = p.checkpoint();
    Chunk spiked = test::cut(run, bad, c.first, c.count);
    spiked.samples.col(3).segment(c.spike - c.first, 200).setConstant(1e200);
    spiked.seal();
    test::expect_input_error([&] { p.push(spiked); }, {"locked_driveline", "non-finite row"});
    EXPECT_EQ(p.checkpoint(), before) << "bad chunk at " << c.first;
    feed(p, run, sizes, bad);
    p.finish();
    RunProcessor whole(run.announcement, wide);
    feed(whole, run, sizes);
    whole.finish();
    expect_bit_identical(p, whole);
    EXPECT_EQ(p.checkpoint(), whole.checkpoint()) << "bad chunk at " << c.first;
  }
}

// What a push keeps to undo itself holds no copy of the filter's pending rows and stays small,
// the row window keeps no room between pushes, and the filter keeps the room of
// StreamingZeroPhaseFilter::held_buffers, over any number of chunks and segments.
TEST(RunProcessor, HeldBuffersStayBoundedOverManyChunks) {
  const TestRun run = test::make_run(6000);  // with gaps: three segments
  RunProcessor p(run.announcement);
  const signal::StreamingZeroPhaseFilter f(p.filter(), 5,
                                           run.announcement.preprocessing.filter_tolerance);
  const std::size_t filtered_row = 5 * sizeof(double);  // all channels but the gear
  const std::size_t window_row = (6 + p.derived_channels().size()) * sizeof(double);
  const auto unit = static_cast<std::size_t>(f.overlap() + f.block());
  Eigen::Index at = 0;
  for (std::size_t k = 0; at + 10 <= run.samples.rows(); ++k, at += 10) {
    p.push(test::cut(run, k, at, 10));
    std::size_t pending_buffers = 0;
    for (const signal::HeldBuffer& b : p.held_buffers()) {
      if (b.name.find("pending") != std::string::npos) ++pending_buffers;
      if (b.name == "segment filter pending") {
        EXPECT_LE(b.allocated, 2 * unit * filtered_row) << "after chunk " << k;
      } else if (b.name == "segment row window") {
        EXPECT_EQ(b.allocated, b.held) << "after chunk " << k;  // no room between pushes
      } else if (b.name.find(" undo ") != std::string::npos ||
                 b.name.find(" mark ") != std::string::npos) {
        EXPECT_LE(b.allocated, unit * window_row) << b.name << " after chunk " << k;
      }
    }
    EXPECT_EQ(pending_buffers, 1u);
  }
}

TEST(RunProcessor, ModelsWithoutTheirChannelsAreNotRunAndBadUnitsAreRejected) {
  TestRun run = test::make_run(1000);
  run.announcement.models.push_back({"kinematic_lateral", {}, {}});
  RunProcessor p(run.announcement);
  EXPECT_EQ(p.groups(3), nullptr);
  const std::vector<std::pair<std::string, std::string>> derived = p.derived_channels();
  ASSERT_EQ(derived.size(), 2u);
  EXPECT_EQ(derived[0], (std::pair<std::string, std::string>{"d_vx", "m/s^2"}));
  EXPECT_EQ(derived[1], (std::pair<std::string, std::string>{"d_engine_speed", "rad/s^2"}));
  const std::vector<ModelEstimate> before = p.estimates();
  EXPECT_EQ(before[0].note, "no rows yet");
  EXPECT_NE(before[3].note.find("not run"), std::string::npos) << before[3].note;
  EXPECT_NE(before[3].note.find("'ay'"), std::string::npos) << before[3].note;
  RunAnnouncement kmh = test::announcement_for({});
  kmh.channels[0].unit = "km/h";
  test::expect_input_error([&] { RunProcessor bad(kmh); }, {"'vx'", "km/h"});
  RunAnnouncement unknown = test::announcement_for({});
  unknown.models[0].effects = {"warp_drive"};
  EXPECT_THROW(RunProcessor bad(unknown), InputError);
}

}  // namespace
}  // namespace dynid::ingest
