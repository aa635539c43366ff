#pragma once
// Zero-phase (forward-backward) filtering of a signal that arrives in chunks, with a bounded
// delay and bounded memory: what the server runs for each run's channel set.
//
// How: the forward pass is causal, so it runs exactly as the offline filter runs it, once the
// first padlen + 1 samples (needed for the odd extension at the start) are in. The backward pass
// would need the whole future; instead, samples are released in fixed blocks of block() samples,
// [b block, (b + 1) block), and block b is swept backward from forward output
// (b + 1) block + overlap - 1, started from the steady state for that value: every released
// sample has at least `overlap` samples of decay behind it. The error this makes at a sample is
// the filter's impulse response beyond `overlap` samples applied to the (bounded) signal
// variation, so the overlap is chosen from the filter's own decay (its impulse response tail) to keep
//     |streamed - zero_phase_filter(whole signal)| <= tolerance * max|x|   (per channel).
// finish() handles the end exactly as the offline filter does (odd extension, steady state), so
// the last samples, and the first ones, match the offline filter to rounding error.
//
// Chunking invariance: where a backward sweep starts depends only on the sample index (the
// block grid), never on where the chunks end, and every operation runs sample by sample, so the
// output is the same to the bit however the signal is cut into chunks (what lets a server's
// result equal the offline processing of the same data). The price: each block costs a backward
// sweep of overlap + block samples, about 1 + overlap / block = 5 backward steps per sample.
//
// Delay rule: output sample k is returned by the push() that brings the number of input samples
// to at least k + delay() + 1, with delay() = overlap() + block() - 1 and block() =
// max(1, overlap() / 4) (the backward pass is run once per block of released samples; a smaller
// block would cut the delay but cost a backward sweep of length overlap + block per block).
// Memory between calls: O((overlap + block) x channels), whatever the length of the signal.
#include <Eigen/Core>

#include <vector>

#include "dynid/signal/held_buffer.hpp"
#include "dynid/signal/sos.hpp"

namespace dynid::signal {

class StreamingZeroPhaseFilter {
 public:
  // tolerance: bound on the error relative to max|x|, in [1e-13, 1e-3]; channels >= 1.
  // Throws InputError otherwise.
  StreamingZeroPhaseFilter(Sos sos, Eigen::Index channels, double tolerance = 1e-10);
  // Copies carry the held samples only, not the spare buffer room; a copy assigned into a filter
  // of the same shape reuses its buffers. (To undo a push, mark() is cheaper than a copy.)
  StreamingZeroPhaseFilter(const StreamingZeroPhaseFilter& other);
  StreamingZeroPhaseFilter& operator=(const StreamingZeroPhaseFilter& other);
  StreamingZeroPhaseFilter(StreamingZeroPhaseFilter&&) noexcept = default;
  StreamingZeroPhaseFilter& operator=(StreamingZeroPhaseFilter&&) noexcept = default;
  ~StreamingZeroPhaseFilter() = default;

  // chunk: rows = samples, one column per channel (any number of rows, including 0). Returns the
  // output samples that became final, in order, continuing the previous returns.
  // Throws InputError, leaving the filter unchanged, when the column count is wrong, a sample is
  // NaN or infinite (naming channel and sample index in the whole stream), or after finish().
  Eigen::MatrixXd push(const Eigen::MatrixXd& chunk);

  // Ends the signal and returns the remaining output samples. Throws InputError, leaving the
  // filter unchanged, when fewer than padlen + 1 samples were pushed (as the offline filter) or
  // when already finished.
  Eigen::MatrixXd finish();

  // Forgets the signal, keeps the filter: ready for a new one.
  void reset();

  // Undo, for a caller that must reject its input after feeding the filter (a server whose model
  // rejects a chunk): mark() saves the state; push(), finish() and reset() may follow; rollback()
  // returns to the mark, to the bit; commit() keeps what was done. Both drop the mark (rollback()
  // without one is a logic_error). Cheaper than a copy: the held forward outputs, most of the
  // state, are not copied, only kept in place until the mark is dropped (the buffer may hold
  // them and the new ones together meanwhile). Copies and restore() carry no mark.
  void mark();
  void rollback();
  void commit();

  // The complete state between calls, exact: restored into a filter built with the same Sos,
  // channel count and tolerance, it continues the signal to the bit (for checkpoints).
  struct State {
    Eigen::Index samples_in = 0;
    Eigen::Index samples_out = 0;
    bool finished = false;
    Eigen::MatrixXd head;           // raw samples while fewer than padlen + 1 are in
    Eigen::MatrixXd raw_tail;       // the last min(samples_in, padlen + 1) raw samples
    Eigen::MatrixXd forward_state;  // 2 per section x channels
    Eigen::MatrixXd pending;        // forward outputs not yet released (samples_out onwards)
  };
  State state() const;
  // Throws InputError, leaving the filter unchanged, when the state cannot be this filter's
  // (shapes, counts, block alignment, non-finite values).
  void restore(const State& state);

  Eigen::Index channels() const { return channels_; }
  Eigen::Index padlen() const { return padlen_; }
  Eigen::Index overlap() const { return overlap_; }
  Eigen::Index block() const { return block_; }
  Eigen::Index delay() const { return overlap_ + block_ - 1; }
  Eigen::Index samples_in() const { return n_in_; }
  Eigen::Index samples_out() const { return n_out_; }
  // Samples held between calls (raw ones before the forward pass starts, then forward outputs
  // not yet released): at most delay() after any push().
  Eigen::Index buffered_samples() const { return head_.rows() + pending_rows_; }
  bool finished() const { return finished_; }
  // The buffers held between calls (head, raw tail, forward state, pending, and what mark()
  // keeps), each with its allocated and held bytes: for memory accounting. The pending buffer's
  // room after a push of m rows: max(overlap() + block(), the rows held before it + m), at most
  // twice that when a longer chunk grew it before; a copy has none.
  std::vector<HeldBuffer> held_buffers() const;

 private:
  void start_forward();
  void forward_into_pending(const Eigen::MatrixXd& x);
  Eigen::MatrixXd release(Eigen::Index blocks);
  void check_state(const State& state) const;
  void keep_raw_tail(const Eigen::MatrixXd& chunk);
  void copy_pending(const StreamingZeroPhaseFilter& other);
  void make_room(Eigen::Index rows);
  void shrink_room();
  void drop_pending();
  // The pending buffer's least room: overlap() + block() rows.
  Eigen::Index usual_room() const;

  Sos sos_;
  Eigen::VectorXd unit_state_;  // steady state of the cascade for a unit constant input
  Eigen::Index channels_;
  Eigen::Index padlen_;
  Eigen::Index overlap_;
  Eigen::Index block_;

  Eigen::Index n_in_ = 0;
  Eigen::Index n_out_ = 0;
  bool finished_ = false;
  Eigen::MatrixXd head_;           // raw samples until padlen + 1 are in (the forward pass waits)
  Eigen::MatrixXd raw_tail_;       // last padlen + 1 raw samples, for the odd extension at the end
  Eigen::MatrixXd forward_state_;  // 2 per section x channels
  // Forward outputs of samples n_out_.., rows [pending_first_, pending_first_ + pending_rows_):
  // releasing advances pending_first_, and the rows are moved up only when the room runs out.
  Eigen::MatrixXd pending_;
  Eigen::Index pending_first_ = 0;
  Eigen::Index pending_rows_ = 0;
  Eigen::Index room_need_ = 0;  // rows the last push had to hold: held before it + new ones

  // The state at mark(): the pending rows [pending_first, pending_end) stay in the buffer (moved
  // only together with the newer rows) while marked_.
  struct Mark {
    Eigen::Index samples_in = 0;
    Eigen::Index samples_out = 0;
    bool finished = false;
    Eigen::MatrixXd head;
    Eigen::MatrixXd raw_tail;
    Eigen::MatrixXd forward_state;
    Eigen::Index pending_first = 0;
    Eigen::Index pending_end = 0;
  };
  Mark mark_;
  bool marked_ = false;
};

// The number of samples after which the tail of the impulse response of `sos` is small enough
// for StreamingZeroPhaseFilter: the smallest L with 6 ||h||_1 sum_{m > L} |h[m]| <= tolerance.
// (6 ||h||_1 bounds the variation of a forward-filtered, odd-extended signal relative to max|x|.)
Eigen::Index zero_phase_overlap(const Sos& sos, double tolerance);

}  // namespace dynid::signal
