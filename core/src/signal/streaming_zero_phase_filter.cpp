#include "dynid/signal/streaming_zero_phase_filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "cascade.hpp"
#include "checks.hpp"
#include "dynid/error.hpp"
#include "dynid/signal/zero_phase_filter.hpp"

namespace dynid::signal {
namespace {

void check_tolerance(double tolerance) {
  // Below 1e-13 the tail sum is lost in the rounding of the total it is taken from.
  if (!(tolerance >= 1e-13 && tolerance <= 1e-3))
    throw InputError("zero-phase streaming: tolerance " + std::to_string(tolerance) +
                     " must be within [1e-13, 1e-3]");
}

// Largest pole modulus of the cascade (< 1: Sos only holds stable sections).
double pole_radius(const Sos& sos) {
  double radius = 0.0;
  for (const Biquad& s : sos.sections()) {
    const double disc = s.a1 * s.a1 - 4.0 * s.a2;
    const double r =
        disc < 0.0 ? std::sqrt(s.a2) : 0.5 * (std::abs(s.a1) + std::sqrt(disc));  // the larger root
    radius = std::max(radius, r);
  }
  return radius;
}

// Calls visit(|h[m]|) for the impulse response h of the cascade until what is left in its
// delays is negligible (1e-30 of their peak): the rest of h is then below any tolerance here.
template <class Visit>
void impulse_magnitudes(const Sos& sos, Visit visit) {
  const double radius = pole_radius(sos);
  const double horizon = std::log(1e-30) / std::log(std::max(radius, 1e-300));
  if (horizon > 1e8)
    throw InputError("zero-phase streaming: the filter decays too slowly (pole radius " +
                     std::to_string(radius) + "); lower the sample rate or raise the cut-off");
  Eigen::VectorXd z = Eigen::VectorXd::Zero(2 * sos.size());
  double input = 1.0;
  double peak = 0.0;
  for (;;) {
    const double h = detail::step(sos.sections(), z.data(), input);
    input = 0.0;
    if (!visit(std::abs(h))) return;
    const double level = z.cwiseAbs().maxCoeff();
    peak = std::max(peak, level);
    if (level <= 1e-30 * peak) return;
  }
}

// Channels run through the cascade L at a time (detail::step_lanes), interleaved in a buffer.
template <int L>
struct Lanes {
  std::vector<double> data;  // sample k of lane l at data[k * L + l]
  std::vector<double> z;     // delay i of lane l at z[i * L + l]

  // Rows [first, first + n) of columns [c, c + L) of m.
  void gather(const Eigen::MatrixXd& m, Eigen::Index first, Eigen::Index n, Eigen::Index c) {
    data.resize(static_cast<std::size_t>(n * L));
    for (int l = 0; l < L; ++l) {
      const double* src = m.col(c + l).data() + first;
      for (Eigen::Index k = 0; k < n; ++k) data[static_cast<std::size_t>(k * L + l)] = src[k];
    }
  }
  // The first n rows of the lanes into rows [first, first + n) of columns [c, c + L) of m.
  void scatter(Eigen::MatrixXd& m, Eigen::Index first, Eigen::Index n, Eigen::Index c) const {
    for (int l = 0; l < L; ++l) {
      double* dst = m.col(c + l).data() + first;
      for (Eigen::Index k = 0; k < n; ++k) dst[k] = data[static_cast<std::size_t>(k * L + l)];
    }
  }
  void z_from(const Eigen::MatrixXd& state, Eigen::Index c) {
    z.resize(static_cast<std::size_t>(state.rows() * L));
    for (Eigen::Index i = 0; i < state.rows(); ++i)
      for (int l = 0; l < L; ++l) z[static_cast<std::size_t>(i * L + l)] = state(i, c + l);
  }
  void z_to(Eigen::MatrixXd& state, Eigen::Index c) const {
    for (Eigen::Index i = 0; i < state.rows(); ++i)
      for (int l = 0; l < L; ++l) state(i, c + l) = z[static_cast<std::size_t>(i * L + l)];
  }
  // Each lane in steady state for its sample k (unit_state * that value, as the scalar path).
  void z_steady(const Eigen::VectorXd& unit_state, Eigen::Index k) {
    z.resize(static_cast<std::size_t>(unit_state.size() * L));
    for (Eigen::Index i = 0; i < unit_state.size(); ++i)
      for (int l = 0; l < L; ++l)
        z[static_cast<std::size_t>(i * L + l)] =
            unit_state(i) * data[static_cast<std::size_t>(k * L + l)];
  }
};

// Forward pass of rows x[0, m) into pending rows [at, at + m), from column c on, L channels at a
// time while L are left; returns the first column not done.
template <int L>
Eigen::Index forward_lanes(const Sos& sos, const Eigen::MatrixXd& x, Eigen::MatrixXd& pending,
                           Eigen::Index at, Eigen::MatrixXd& state, Eigen::Index c) {
  Lanes<L> lanes;
  for (; c + L <= x.cols(); c += L) {
    lanes.gather(x, 0, x.rows(), c);
    lanes.z_from(state, c);
    detail::run_forward_lanes<L>(sos, lanes.z.data(), lanes.data.data(), x.rows());
    lanes.z_to(state, c);
    lanes.scatter(pending, at, x.rows(), c);
  }
  return c;
}

// What a block sweep reads and writes: pending rows from `first`, blocks of `block` released
// into `out`, each swept backward over `span` samples from steady state.
struct Sweep {
  const Sos& sos;
  const Eigen::VectorXd& unit_state;
  const Eigen::MatrixXd& pending;
  Eigen::Index first, blocks, block, span;
  Eigen::MatrixXd& out;
};

// Backward sweeps of every block, from column c on, L channels at a time while L are left;
// returns the first column not done.
template <int L>
Eigen::Index sweep_lanes(const Sweep& w, Eigen::Index c) {
  Lanes<L> lanes;
  for (; c + L <= w.pending.cols(); c += L)
    for (Eigen::Index b = 0; b < w.blocks; ++b) {
      lanes.gather(w.pending, w.first + b * w.block, w.span, c);
      lanes.z_steady(w.unit_state, w.span - 1);
      detail::run_backward_lanes<L>(w.sos, lanes.z.data(), lanes.data.data(), w.span);
      lanes.scatter(w.out, b * w.block, w.block, c);
    }
  return c;
}

}  // namespace

Eigen::Index zero_phase_overlap(const Sos& sos, double tolerance) {
  check_tolerance(tolerance);
  double norm1 = 0.0;
  impulse_magnitudes(sos, [&](double a) {
    norm1 += a;
    return true;
  });
  // Error at a released sample <= sum_{m > L} |h[m]| * max|u - u_j| with u the forward output,
  // |u| <= ||h||_1 * 3 max|x| (odd extension values reach 3 max|x|), so the variation <= 6 ...
  const double allowed_tail = tolerance / (6.0 * norm1);
  double prefix = 0.0;
  Eigen::Index count = 0;
  impulse_magnitudes(sos, [&](double a) {
    prefix += a;
    ++count;
    return norm1 - prefix > allowed_tail;
  });
  // h[0..count) summed: what is left, h[m] for m > count - 1, is small enough.
  return std::max<Eigen::Index>(1, count - 1);
}

StreamingZeroPhaseFilter::StreamingZeroPhaseFilter(Sos sos, Eigen::Index channels, double tolerance)
    : sos_(std::move(sos)),
      unit_state_(detail::unit_steady_state(sos_)),
      channels_(channels),
      padlen_(zero_phase_padlen(sos_)),
      overlap_(std::max(zero_phase_overlap(sos_, tolerance), padlen_ + 1)),
      block_(std::max<Eigen::Index>(1, overlap_ / 4)) {
  detail::require_channel_count(channels, "StreamingZeroPhaseFilter");
  reset();
}

StreamingZeroPhaseFilter::StreamingZeroPhaseFilter(const StreamingZeroPhaseFilter& other)
    : sos_(other.sos_),
      unit_state_(other.unit_state_),
      channels_(other.channels_),
      padlen_(other.padlen_),
      overlap_(other.overlap_),
      block_(other.block_),
      n_in_(other.n_in_),
      n_out_(other.n_out_),
      finished_(other.finished_),
      head_(other.head_),
      raw_tail_(other.raw_tail_),
      forward_state_(other.forward_state_) {
  copy_pending(other);
}

StreamingZeroPhaseFilter& StreamingZeroPhaseFilter::operator=(const StreamingZeroPhaseFilter& other) {
  if (this == &other) return *this;
  sos_ = other.sos_;
  unit_state_ = other.unit_state_;
  channels_ = other.channels_;
  padlen_ = other.padlen_;
  overlap_ = other.overlap_;
  block_ = other.block_;
  n_in_ = other.n_in_;
  n_out_ = other.n_out_;
  finished_ = other.finished_;
  head_ = other.head_;
  raw_tail_ = other.raw_tail_;
  forward_state_ = other.forward_state_;
  copy_pending(other);
  marked_ = false;
  return *this;
}

void StreamingZeroPhaseFilter::copy_pending(const StreamingZeroPhaseFilter& other) {
  const Eigen::Index rows = other.pending_rows_;
  if (pending_.cols() != channels_ || pending_.rows() < rows) pending_.resize(rows, channels_);
  pending_.topRows(rows) = other.pending_.middleRows(other.pending_first_, rows);
  pending_first_ = 0;
  pending_rows_ = rows;
}

void StreamingZeroPhaseFilter::reset() {
  n_in_ = 0;
  n_out_ = 0;
  finished_ = false;
  head_.resize(0, channels_);
  raw_tail_.resize(0, channels_);
  forward_state_.setZero(unit_state_.size(), channels_);  // defined before start: state() copies it
  drop_pending();
}

void StreamingZeroPhaseFilter::drop_pending() {
  pending_rows_ = 0;
  if (marked_) {  // the marked rows stay where they are; new ones go after them
    pending_first_ = mark_.pending_end;
    return;
  }
  pending_.resize(0, channels_);
  pending_first_ = 0;
}

void StreamingZeroPhaseFilter::mark() {
  mark_.samples_in = n_in_;
  mark_.samples_out = n_out_;
  mark_.finished = finished_;
  mark_.head = head_;
  mark_.raw_tail = raw_tail_;
  mark_.forward_state = forward_state_;
  mark_.pending_first = pending_first_;
  mark_.pending_end = pending_first_ + pending_rows_;
  marked_ = true;
}

void StreamingZeroPhaseFilter::rollback() {
  if (!marked_) throw std::logic_error("StreamingZeroPhaseFilter::rollback: no mark");
  n_in_ = mark_.samples_in;
  n_out_ = mark_.samples_out;
  finished_ = mark_.finished;
  head_ = mark_.head;
  raw_tail_ = mark_.raw_tail;
  forward_state_ = mark_.forward_state;
  pending_first_ = mark_.pending_first;
  pending_rows_ = mark_.pending_end - mark_.pending_first;
  commit();
}

void StreamingZeroPhaseFilter::commit() {
  marked_ = false;
  if (pending_rows_ == 0 && (finished_ || n_in_ <= padlen_)) {  // as drop_pending() unmarked
    pending_.resize(0, channels_);
    pending_first_ = 0;
  }
  shrink_room();
}

Eigen::MatrixXd StreamingZeroPhaseFilter::push(const Eigen::MatrixXd& chunk) {
  const char* what = "StreamingZeroPhaseFilter::push";
  if (finished_) throw InputError(std::string(what) + ": the signal was finished; reset() first");
  detail::require_columns(chunk, channels_, what);
  detail::require_finite(chunk, n_in_, what);
  // Checks done: from here on the state changes.
  if (chunk.rows() == 0) return Eigen::MatrixXd(0, channels_);
  keep_raw_tail(chunk);
  const bool started = n_in_ > padlen_;
  n_in_ += chunk.rows();
  if (started) {
    forward_into_pending(chunk);
  } else {
    head_.conservativeResize(head_.rows() + chunk.rows(), Eigen::NoChange);
    head_.bottomRows(chunk.rows()) = chunk;
    if (n_in_ > padlen_) start_forward();
  }
  // Whole blocks only: the block grid, not the chunk end, fixes where backward sweeps start.
  const Eigen::Index blocks = std::max<Eigen::Index>(0, pending_rows_ - overlap_) / block_;
  return blocks > 0 ? release(blocks) : Eigen::MatrixXd(0, channels_);
}

Eigen::MatrixXd StreamingZeroPhaseFilter::finish() {
  if (finished_) throw InputError("StreamingZeroPhaseFilter::finish: already finished");
  if (n_in_ <= padlen_)
    throw InputError("StreamingZeroPhaseFilter::finish: the signal has " + std::to_string(n_in_) +
                     " samples; the edge padding needs more than " + std::to_string(padlen_));
  Eigen::MatrixXd out(pending_rows_, channels_);
  Eigen::VectorXd pad(padlen_);
  Eigen::VectorXd z(unit_state_.size());
  for (Eigen::Index c = 0; c < channels_; ++c) {
    // The end exactly as the offline filter: forward through the odd extension, then back
    // from its steady state over the extension and every sample not yet released.
    detail::odd_pad_end(raw_tail_.col(c).data(), raw_tail_.rows(), padlen_, pad.data());
    detail::run_forward(sos_, forward_state_.col(c).data(), pad.data(), padlen_);
    z = unit_state_ * pad(padlen_ - 1);
    detail::run_backward(sos_, z.data(), pad.data(), padlen_);
    out.col(c) = pending_.col(c).segment(pending_first_, pending_rows_);
    detail::run_backward(sos_, z.data(), out.col(c).data(), pending_rows_);
  }
  n_out_ += pending_rows_;
  drop_pending();
  finished_ = true;
  return out;
}

void StreamingZeroPhaseFilter::keep_raw_tail(const Eigen::MatrixXd& chunk) {
  const Eigen::Index keep = padlen_ + 1;
  if (chunk.rows() >= keep) {
    raw_tail_ = chunk.bottomRows(keep);
    return;
  }
  Eigen::MatrixXd joined(raw_tail_.rows() + chunk.rows(), channels_);
  joined << raw_tail_, chunk;
  raw_tail_ = joined.bottomRows(std::min(keep, joined.rows()));
}

void StreamingZeroPhaseFilter::start_forward() {
  // The odd extension before the start needs x[0..padlen]: the forward pass waits for it.
  Eigen::VectorXd pad(padlen_);
  for (Eigen::Index c = 0; c < channels_; ++c) {
    detail::odd_pad_start(head_.col(c).data(), padlen_, pad.data());
    forward_state_.col(c) = unit_state_ * pad(0);
    detail::run_forward(sos_, forward_state_.col(c).data(), pad.data(), padlen_);
  }
  const Eigen::MatrixXd head = std::move(head_);
  head_.resize(0, channels_);
  forward_into_pending(head);
}

Eigen::Index StreamingZeroPhaseFilter::usual_room() const {
  // Held rows stay below overlap + block after a push. The room is what a push needs (held
  // rows and its chunk), no more: the held rows then move up at about every push, a memmove of
  // < 1/4 of what the release's sweeps read (measured: +0.4 % instructions per push), for
  // (overlap + block) x channels doubles less memory per run.
  return overlap_ + block_;
}

void StreamingZeroPhaseFilter::make_room(Eigen::Index m) {
  // Room for m more rows after the held ones: move the held rows to the top (one block move per
  // channel, seldom: only when the rows released since the last move leave too little room),
  // and grow only when they alone do not fit. Under a mark, the marked rows move with them.
  const Eigen::Index end = pending_first_ + pending_rows_;
  const Eigen::Index from =
      marked_ ? std::min(pending_first_, mark_.pending_first) : pending_first_;
  room_need_ = end - from + m;
  if (end + m <= pending_.rows()) return;
  if (from > 0) {
    for (Eigen::Index c = 0; c < channels_; ++c) {
      double* col = pending_.col(c).data();
      std::memmove(col, col + from, sizeof(double) * static_cast<std::size_t>(end - from));
    }
    pending_first_ -= from;
    mark_.pending_first -= from;
    mark_.pending_end -= from;
  }
  if (pending_.rows() < room_need_)
    pending_.conservativeResize(std::max(room_need_, usual_room()), Eigen::NoChange);
}

void StreamingZeroPhaseFilter::forward_into_pending(const Eigen::MatrixXd& x) {
  const Eigen::Index m = x.rows();
  make_room(m);
  const Eigen::Index at = pending_first_ + pending_rows_;
  // Wide groups first (more independent chains in flight), then what is left.
  Eigen::Index c = forward_lanes<8>(sos_, x, pending_, at, forward_state_, 0);
  c = forward_lanes<4>(sos_, x, pending_, at, forward_state_, c);
  c = forward_lanes<2>(sos_, x, pending_, at, forward_state_, c);
  for (; c < channels_; ++c) {  // the last one, if any: the same operations
    pending_.col(c).segment(at, m) = x.col(c);
    detail::run_forward(sos_, forward_state_.col(c).data(), pending_.col(c).data() + at, m);
  }
  pending_rows_ += m;
}

Eigen::MatrixXd StreamingZeroPhaseFilter::release(Eigen::Index blocks) {
  // Block b (pending rows [b block, (b + 1) block)) is swept backward from the forward output
  // `overlap` samples past its end, started in steady state for that value.
  const Eigen::Index count = blocks * block_;
  const Eigen::Index span = block_ + overlap_;
  Eigen::MatrixXd out(count, channels_);
  const Sweep w{sos_, unit_state_, pending_, pending_first_, blocks, block_, span, out};
  Eigen::Index c = sweep_lanes<8>(w, 0);
  c = sweep_lanes<4>(w, c);
  c = sweep_lanes<2>(w, c);
  Eigen::VectorXd sweep(span);
  Eigen::VectorXd z(unit_state_.size());
  for (; c < channels_; ++c) {  // the last one, if any: the same operations
    for (Eigen::Index b = 0; b < blocks; ++b) {
      sweep = pending_.col(c).segment(pending_first_ + b * block_, span);
      z = unit_state_ * sweep(span - 1);
      detail::run_backward(sos_, z.data(), sweep.data(), span);
      out.col(c).segment(b * block_, block_) = sweep.head(block_);
    }
  }
  pending_first_ += count;
  pending_rows_ -= count;
  n_out_ += count;
  shrink_room();
  return out;
}

void StreamingZeroPhaseFilter::shrink_room() {
  // A chunk much longer than the last one grew the buffer: give the memory back so idle runs
  // stay small (not under a mark: the marked rows may not move). Room for the last push's need
  // stays, so that chunks of one size do not reallocate at every push.
  const Eigen::Index keep = std::max(usual_room(), room_need_);
  if (marked_ || pending_.rows() <= 2 * keep) return;
  pending_.topRows(pending_rows_) = pending_.middleRows(pending_first_, pending_rows_).eval();
  pending_first_ = 0;
  pending_.conservativeResize(keep, Eigen::NoChange);
}

StreamingZeroPhaseFilter::State StreamingZeroPhaseFilter::state() const {
  return {n_in_, n_out_, finished_, head_, raw_tail_, forward_state_,
          pending_.middleRows(pending_first_, pending_rows_)};
}

std::vector<HeldBuffer> StreamingZeroPhaseFilter::held_buffers() const {
  return {held_buffer("filter head", head_, head_.rows()),
          held_buffer("filter raw tail", raw_tail_, raw_tail_.rows()),
          held_buffer("filter forward state", forward_state_, forward_state_.rows()),
          held_buffer("filter pending", pending_, pending_rows_),
          held_buffer("filter mark head", mark_.head, mark_.head.rows()),
          held_buffer("filter mark raw tail", mark_.raw_tail, mark_.raw_tail.rows()),
          held_buffer("filter mark forward state", mark_.forward_state,
                      mark_.forward_state.rows())};
}

void StreamingZeroPhaseFilter::check_state(const State& s) const {
  const auto fail = [](const std::string& why) {
    throw InputError("StreamingZeroPhaseFilter::restore: " + why);
  };
  const bool started = s.samples_in > padlen_;
  if (s.samples_in < 0 || s.samples_out < 0 || s.samples_out > s.samples_in)
    fail("sample counts out of range");
  if (s.head.cols() != channels_ || s.raw_tail.cols() != channels_ ||
      s.pending.cols() != channels_ || s.forward_state.cols() != channels_)
    fail("channel count differs from the filter's " + std::to_string(channels_));
  if (s.forward_state.rows() != unit_state_.size()) fail("forward state of another filter");
  if (s.head.rows() != (started ? 0 : s.samples_in)) fail("raw head does not match the count");
  if (s.raw_tail.rows() != std::min(s.samples_in, padlen_ + 1)) fail("raw tail length");
  const Eigen::Index pending = started && !s.finished ? s.samples_in - s.samples_out : 0;
  if (s.pending.rows() != pending) fail("pending forward outputs do not match the counts");
  if (!s.finished && s.samples_out % block_ != 0) fail("output count off the block grid");
  if (!s.head.allFinite() || !s.raw_tail.allFinite() || !s.forward_state.allFinite() ||
      !s.pending.allFinite())
    fail("non-finite value");
}

void StreamingZeroPhaseFilter::restore(const State& s) {
  check_state(s);
  n_in_ = s.samples_in;
  n_out_ = s.samples_out;
  finished_ = s.finished;
  head_ = s.head;
  raw_tail_ = s.raw_tail;
  forward_state_ = s.forward_state;
  pending_ = s.pending;
  pending_first_ = 0;
  pending_rows_ = s.pending.rows();
  marked_ = false;
}

}  // namespace dynid::signal
