// Streaming zero-phase filter: equal to the offline filter for any chunking, delay as documented,
// rejected input leaves it unchanged.
#include "dynid/signal/streaming_zero_phase_filter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid/error.hpp"
#include "dynid/signal/butterworth.hpp"
#include "dynid/signal/zero_phase_filter.hpp"
#include "test_support.hpp"

namespace dynid::signal {
namespace {

// Feeds x in chunks of the given sizes (cycled), checking the delay rule after every push;
// returns everything the filter released, finish() included.
Eigen::MatrixXd stream(StreamingZeroPhaseFilter& filter, const Eigen::MatrixXd& x,
                       const std::vector<Eigen::Index>& sizes) {
  Eigen::MatrixXd y(x.rows(), x.cols());
  Eigen::Index in = 0;
  Eigen::Index out = 0;
  for (std::size_t i = 0; in < x.rows(); ++i) {
    const Eigen::Index m = std::min(sizes[i % sizes.size()], x.rows() - in);
    const Eigen::MatrixXd got = filter.push(x.middleRows(in, m));
    in += m;
    y.middleRows(out, got.rows()) = got;
    out += got.rows();
    EXPECT_EQ(filter.samples_out(), out);
    // Output sample k is released once input sample k + delay is in.
    EXPECT_GE(out, in - filter.delay()) << "after " << in << " samples";
    // Bounded state: never the whole signal.
    EXPECT_LE(filter.buffered_samples(), filter.delay()) << "after " << in << " samples";
  }
  const Eigen::MatrixXd tail = filter.finish();
  EXPECT_EQ(out + tail.rows(), x.rows());
  y.bottomRows(tail.rows()) = tail;
  return y;
}

std::vector<Eigen::Index> random_sizes(Eigen::Index largest, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Eigen::Index> size(1, largest);
  std::vector<Eigen::Index> sizes(500);
  for (auto& s : sizes) s = size(rng);
  return sizes;
}

struct Case {
  int order;
  double cutoff_hz;
  double rate_hz;
};

class StreamingEqualsOffline : public testing::TestWithParam<Case> {};

TEST_P(StreamingEqualsOffline, ForAnyChunking) {
  const Case c = GetParam();
  const Sos sos = butterworth_lowpass(c.order, c.cutoff_hz, c.rate_hz);
  StreamingZeroPhaseFilter filter(sos, 2);
  const Eigen::Index n = 3 * filter.delay() + 1234;
  const Eigen::MatrixXd x = test::test_signal(n, 2, 42u);
  const Eigen::MatrixXd offline = zero_phase_filter(sos, x);
  const double scale = x.cwiseAbs().maxCoeff();
  const std::vector<std::vector<Eigen::Index>> chunkings = {
      {1}, random_sizes(filter.overlap() / 3 + 1, 7u), random_sizes(3 * filter.delay(), 8u), {n}};
  for (const auto& sizes : chunkings) {
    filter.reset();
    const Eigen::MatrixXd streamed = stream(filter, x, sizes);
    // Everywhere, the ends included: they are handled exactly as offline.
    EXPECT_LT((streamed - offline).cwiseAbs().maxCoeff(), 1e-9 * scale)
        << "first chunk size " << sizes.front() << ", overlap " << filter.overlap();
  }
}

std::string case_name(const testing::TestParamInfo<Case>& info) {
  const Case& c = info.param;
  return "order" + std::to_string(c.order) + "_fc" + std::to_string(static_cast<int>(c.cutoff_hz)) +
         "_fs" + std::to_string(static_cast<int>(c.rate_hz));
}

INSTANTIATE_TEST_SUITE_P(Designs, StreamingEqualsOffline,
                         testing::Values(Case{5, 3.125, 650.0}, Case{2, 10.0, 100.0},
                                         Case{8, 30.0, 100.0}, Case{1, 45.0, 100.0},
                                         Case{4, 100.0, 1000.0}),
                         case_name);

TEST(StreamingZeroPhaseFilter, OutputDoesNotDependOnTheChunkingToTheBit) {
  // Backward sweeps start on the block grid, not at chunk ends: any chunking gives the same
  // bits, which is what makes a server's streamed result equal to its one-chunk result.
  const Sos sos = butterworth_lowpass(5, 4.0, 100.0);
  StreamingZeroPhaseFilter filter(sos, 2, 1e-6);  // loose: chunk-dependent sweeps would show
  const Eigen::MatrixXd x = test::test_signal(5 * filter.delay() + 77, 2, 11u);
  const Eigen::MatrixXd whole = stream(filter, x, {x.rows()});
  for (unsigned seed : {1u, 2u, 3u}) {
    filter.reset();
    const Eigen::MatrixXd chunked = stream(filter, x, random_sizes(2 * filter.block() + 3, seed));
    EXPECT_EQ((chunked - whole).cwiseAbs().maxCoeff(), 0.0) << "seed " << seed;
  }
}

TEST(StreamingZeroPhaseFilter, StateRestoresExactlyAndIsChecked) {
  const Sos sos = butterworth_lowpass(4, 6.0, 100.0);
  const Eigen::MatrixXd x = test::test_signal(900, 3, 5u);
  StreamingZeroPhaseFilter whole(sos, 3);
  const Eigen::MatrixXd expected = stream(whole, x, {x.rows()});
  const Eigen::Index cuts[] = {0, 5, whole.padlen() + 3, 400};
  for (Eigen::Index cut : cuts) {
    StreamingZeroPhaseFilter first(sos, 3);
    Eigen::MatrixXd got(x.rows(), 3);
    const Eigen::MatrixXd a = first.push(x.topRows(cut));
    got.topRows(a.rows()) = a;
    StreamingZeroPhaseFilter second(sos, 3);
    second.restore(first.state());
    const Eigen::MatrixXd b = second.push(x.bottomRows(x.rows() - cut));
    got.middleRows(a.rows(), b.rows()) = b;
    got.bottomRows(x.rows() - a.rows() - b.rows()) = second.finish();
    EXPECT_EQ((got - expected).cwiseAbs().maxCoeff(), 0.0) << "cut at " << cut;
  }
  StreamingZeroPhaseFilter other(sos, 2);
  StreamingZeroPhaseFilter source(sos, 3);
  (void)source.push(x.topRows(300));
  EXPECT_THROW(other.restore(source.state()), InputError);  // channel count
  StreamingZeroPhaseFilter::State bad = source.state();
  bad.samples_in += 1;
  EXPECT_THROW(source.restore(bad), InputError);
  bad = source.state();
  bad.pending(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(source.restore(bad), InputError);
  EXPECT_EQ(source.samples_in(), 300);  // unchanged by the rejections
}

TEST(StreamingZeroPhaseFilter, LooseToleranceStillBoundsTheError) {
  // The overlap comes from the impulse-response tail: with a loose tolerance the error is
  // visible, and must stay within tolerance * max|x|.
  const Sos sos = butterworth_lowpass(4, 5.0, 200.0);
  for (double tolerance : {1e-3, 1e-6, 1e-8}) {
    StreamingZeroPhaseFilter filter(sos, 1, tolerance);
    const Eigen::MatrixXd x = test::test_signal(4 * filter.delay() + 100, 1, 3u);
    const double error = (stream(filter, x, {1}) - zero_phase_filter(sos, x)).cwiseAbs().maxCoeff();
    EXPECT_LE(error, tolerance * x.cwiseAbs().maxCoeff()) << "tolerance " << tolerance;
    EXPECT_GT(error, 0.0);  // the check above is not vacuous: released samples are approximate
  }
}

TEST(StreamingZeroPhaseFilter, OverlapFollowsTheFilterDecay) {
  // Slower poles (lower cut-off relative to the sample rate) need a longer overlap.
  const Eigen::Index fast = zero_phase_overlap(butterworth_lowpass(4, 20.0, 100.0), 1e-10);
  const Eigen::Index slow = zero_phase_overlap(butterworth_lowpass(4, 2.0, 100.0), 1e-10);
  EXPECT_GT(slow, 5 * fast);
  EXPECT_GT(zero_phase_overlap(butterworth_lowpass(4, 2.0, 100.0), 1e-12), slow);
  const StreamingZeroPhaseFilter filter(butterworth_lowpass(4, 2.0, 100.0), 3);
  EXPECT_EQ(filter.overlap(), slow);
  EXPECT_EQ(filter.delay(), filter.overlap() + filter.block() - 1);
}

TEST(StreamingZeroPhaseFilter, RejectedChunkLeavesTheFilterUnchanged) {
  const Sos sos = butterworth_lowpass(3, 8.0, 100.0);
  const Eigen::MatrixXd x = test::test_signal(2000, 3, 9u);
  StreamingZeroPhaseFilter filter(sos, 3);
  Eigen::MatrixXd y(x.rows(), 3);
  Eigen::Index out = 0;
  auto keep = [&](const Eigen::MatrixXd& got) {
    y.middleRows(out, got.rows()) = got;
    out += got.rows();
  };
  keep(filter.push(x.topRows(700)));
  Eigen::MatrixXd bad = x.middleRows(700, 50);
  bad(20, 1) = std::numeric_limits<double>::infinity();
  test::expect_input_error([&] { (void)filter.push(bad); }, "channel 1, sample 720 is infinite");
  EXPECT_THROW((void)filter.push(Eigen::MatrixXd::Zero(5, 2)), InputError);  // wrong columns
  EXPECT_EQ(filter.samples_in(), 700);
  keep(filter.push(x.bottomRows(1300)));
  keep(filter.finish());
  ASSERT_EQ(out, x.rows());
  EXPECT_LT((y - zero_phase_filter(sos, x)).cwiseAbs().maxCoeff(), 1e-9 * x.cwiseAbs().maxCoeff());
  EXPECT_THROW((void)filter.push(x.topRows(1)), InputError);  // after finish
  EXPECT_THROW((void)filter.finish(), InputError);
}

TEST(StreamingZeroPhaseFilter, TooShortSignalIsRejectedThenCanGrow) {
  const Sos sos = butterworth_lowpass(2, 10.0, 100.0);
  StreamingZeroPhaseFilter filter(sos, 1);
  const Eigen::MatrixXd x = test::test_signal(filter.padlen() + 1, 1, 4u);
  EXPECT_EQ(filter.push(x.topRows(filter.padlen())).rows(), 0);
  EXPECT_THROW((void)filter.finish(), InputError);
  EXPECT_FALSE(filter.finished());
  EXPECT_EQ(filter.push(x.bottomRows(1)).rows(), 0);
  const Eigen::MatrixXd y = filter.finish();  // everything comes out of finish(), exactly
  EXPECT_LT((y - zero_phase_filter(sos, x)).cwiseAbs().maxCoeff(), 1e-12);
}

std::size_t pending_allocated(const StreamingZeroPhaseFilter& f) {
  for (const HeldBuffer& b : f.held_buffers())
    if (b.name == "filter pending") return b.allocated;
  ADD_FAILURE() << "no pending buffer listed";
  return 0;
}

TEST(StreamingZeroPhaseFilter, PendingRoomStaysBoundedAndCopiesHaveNone) {
  const Sos sos = butterworth_lowpass(5, 5.0, 100.0);
  StreamingZeroPhaseFilter filter(sos, 3);
  const Eigen::Index unit = filter.overlap() + filter.block();
  const auto rows_of = [&](std::size_t bytes) {
    return static_cast<Eigen::Index>(bytes / (3 * sizeof(double)));
  };
  const Eigen::MatrixXd x = test::test_signal(400 * unit, 3, 5u);
  Eigen::Index in = 0;
  // After a push of m rows: max(unit, held before + m) rows of room, held before < unit.
  for (const Eigen::Index m : random_sizes(unit, 6u)) {  // 500 chunks of at most `unit` rows
    (void)filter.push(x.middleRows(in, m));
    in += m;
    EXPECT_LE(rows_of(pending_allocated(filter)), 2 * unit);
  }
  const StreamingZeroPhaseFilter copy(filter);
  EXPECT_EQ(rows_of(pending_allocated(copy)), filter.buffered_samples());
  StreamingZeroPhaseFilter assigned(sos, 3);
  assigned = filter;
  EXPECT_EQ(rows_of(pending_allocated(assigned)), filter.buffered_samples());
  // At most twice the need of this push or of the one before (a longer chunk grew it; the next
  // release gives the rest back).
  Eigen::Index last = unit;
  const std::vector<Eigen::Index> sizes{20 * unit, unit, 3 * unit, 2 * unit + 1, 1, unit / 2};
  for (const Eigen::Index m : sizes) {
    (void)filter.push(x.middleRows(in, m));
    in += m;
    EXPECT_LE(rows_of(pending_allocated(filter)), 2 * (unit + std::max(m, last)))
        << "after a chunk of " << m;
    last = m;
  }
  EXPECT_LE(rows_of(pending_allocated(filter)), 3 * unit);
}

// Whatever follows mark() (short and long chunks, finish(), a new signal), rollback() returns to
// the marked state to the bit, and the signal then continues as if nothing had come.
TEST(StreamingZeroPhaseFilter, RollbackReturnsToTheMark) {
  const Sos sos = butterworth_lowpass(4, 6.0, 100.0);
  StreamingZeroPhaseFilter filter(sos, 2);
  const Eigen::Index unit = filter.overlap() + filter.block();
  const Eigen::MatrixXd x = test::test_signal(40 * unit, 2, 8u);
  const Eigen::MatrixXd junk = test::test_signal(30 * unit, 2, 9u);
  StreamingZeroPhaseFilter whole(sos, 2);
  const Eigen::MatrixXd expected = stream(whole, x, {unit / 2});
  const auto same_state = [](const StreamingZeroPhaseFilter& a, const StreamingZeroPhaseFilter& b) {
    const StreamingZeroPhaseFilter::State s = a.state();
    const StreamingZeroPhaseFilter::State t = b.state();
    return s.samples_in == t.samples_in && s.samples_out == t.samples_out &&
           s.finished == t.finished && s.head == t.head && s.raw_tail == t.raw_tail &&
           s.forward_state == t.forward_state && s.pending == t.pending;
  };
  Eigen::MatrixXd y(x.rows(), 2);
  Eigen::Index in = 0;
  Eigen::Index out = 0;
  for (int round = 0; in < x.rows(); ++round) {
    const StreamingZeroPhaseFilter before(filter);
    filter.mark();
    switch (round % 4) {  // what a rejected push may have done
      case 0:
        (void)filter.push(junk.topRows(unit / 3));
        break;
      case 1:
        (void)filter.push(junk.topRows(7 * unit));  // grows and moves the buffer
        (void)filter.push(junk.middleRows(7 * unit, unit));
        break;
      case 2:
        if (filter.samples_in() > filter.padlen()) (void)filter.finish();
        filter.reset();
        (void)filter.push(junk.topRows(3 * unit));
        break;
      default:
        (void)filter.push(junk.topRows(20 * unit));
        filter.reset();
    }
    filter.rollback();
    EXPECT_TRUE(same_state(filter, before)) << "round " << round;
    const Eigen::Index m = std::min(unit / 2, x.rows() - in);
    filter.mark();
    const Eigen::MatrixXd got = filter.push(x.middleRows(in, m));
    filter.commit();
    in += m;
    y.middleRows(out, got.rows()) = got;
    out += got.rows();
  }
  const Eigen::MatrixXd tail = filter.finish();
  y.bottomRows(tail.rows()) = tail;
  EXPECT_EQ((y - expected).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_THROW(filter.rollback(), std::logic_error);
}

TEST(StreamingZeroPhaseFilter, RejectsBadSettings) {
  const Sos sos = butterworth_lowpass(2, 10.0, 100.0);
  EXPECT_THROW(StreamingZeroPhaseFilter(sos, 0), InputError);
  EXPECT_THROW(StreamingZeroPhaseFilter(sos, 1, 0.0), InputError);
  EXPECT_THROW(StreamingZeroPhaseFilter(sos, 1, 1e-20), InputError);
  EXPECT_THROW(StreamingZeroPhaseFilter(sos, 1, std::numeric_limits<double>::quiet_NaN()),
               InputError);
}

}  // namespace
}  // namespace dynid::signal
