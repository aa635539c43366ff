#pragma once
// Private to the ingest area: the preprocessing of one valid segment of a run (low-pass,
// pass-through of discrete channels, derivatives) and the window of final samples the models
// read. Segment indices count samples from the segment's first one.
//
// Window: rows [window_first, window_first + window_rows) of the segment, columns = the
// announced channels then the derived ones. A row's announced columns are known once the filter
// released it, its derived columns once the derivative did (derived_end). Rows are built for
// [built, ready_end) with `reach.back` rows of context before and, until the segment ends,
// `reach.ahead` rows after (the models' reach, at least kReachBack/kReachAhead); consume() then
// drops what no later row can reach.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "byte_codec.hpp"
#include "dynid/model/model.hpp"
#include "dynid/signal/derivative.hpp"
#include "dynid/signal/held_buffer.hpp"
#include "dynid/signal/streaming_zero_phase_filter.hpp"

namespace dynid::ingest::detail {

/// Which announced columns are filtered or passed through, and where derived channels come from.
struct Layout {
  std::vector<Eigen::Index> filtered;
  std::vector<Eigen::Index> unfiltered;
  std::vector<Eigen::Index> derived_from;  ///< per derived channel, its announced column
  Eigen::Index announced = 0;
  Eigen::Index width() const { return announced + static_cast<Eigen::Index>(derived_from.size()); }
};

/// What the models may read now: `rows` (a block of the window) of which rows
/// [first_new, first_new + new_count) are the ones to build; row i of `rows` is sample
/// first_index + i of the segment.
struct ReadyRows {
  Eigen::Block<const Eigen::MatrixXd> rows;
  Eigen::Index first_new;
  Eigen::Index new_count;
  Eigen::Index first_index;
};

class SegmentStream {
 public:
  SegmentStream(const signal::Sos& sos, Layout layout, double sample_period, double tolerance,
                model::RowReach reach);
  SegmentStream(const SegmentStream&) = delete;  // one per run; undo is mark()/rollback()
  SegmentStream& operator=(const SegmentStream&) = delete;
  SegmentStream(SegmentStream&&) noexcept = default;
  SegmentStream& operator=(SegmentStream&&) noexcept = default;
  ~SegmentStream() = default;

  /// Starts a new segment at grid index `start` (forgets the previous one).
  void start(std::uint64_t start);
  void stop() { now_.active = false; }
  bool active() const { return now_.active; }
  std::uint64_t start_index() const { return now_.start; }
  Eigen::Index length() const { return filter_.samples_in(); }
  /// Enough samples for the edge extension (otherwise the segment is skipped).
  bool long_enough() const { return filter_.samples_in() > filter_.padlen(); }
  Eigen::Index delay() const { return filter_.delay(); }

  /// Raw valid rows of the segment (all announced columns), in order.
  void push(const Eigen::Ref<const Eigen::MatrixXd>& raw);
  /// Ends the segment: every sample becomes final. Needs long_enough().
  void finish();

  /// Undo of what follows (pushes, finish(), a new segment): mark() saves the state, rollback()
  /// returns to it exactly, commit() keeps the changes (and gives back the window's room: between
  /// pushes it holds a few rows of context); see StreamingZeroPhaseFilter::mark().
  void mark();
  void rollback();
  void commit();

  ReadyRows ready(bool at_end) const;
  /// Marks the `count` rows of the last ready() built; drops rows no later row reaches.
  void consume(Eigen::Index count);

  /// The buffers held between pushes (filter, derivative, FIFO, window), names prefixed.
  void held_buffers(const std::string& prefix, std::vector<signal::HeldBuffer>& out) const;

  void save(ByteWriter& w) const;
  /// Throws InputError (via the reader or the signal classes) when the state does not fit.
  void load(ByteReader& r);

 private:
  void append_final(const Eigen::MatrixXd& filtered);
  void reserve_window(Eigen::Index rows);
  // Rows the window is given first: a filter block, the context and the look-ahead.
  Eigen::Index usual_window() const;

  Layout layout_;
  model::RowReach reach_;
  signal::StreamingZeroPhaseFilter filter_;
  // Everything a push changes but the filter (which undoes itself: mark()).
  struct Rows {
    std::optional<signal::StreamingDerivative> derivative;
    bool active = false;
    std::uint64_t start = 0;
    Eigen::MatrixXd fifo;  // pass-through channels of samples the filter holds back
    Eigen::Index fifo_rows = 0;
    Eigen::MatrixXd window;
    Eigen::Index window_first = 0;
    Eigen::Index window_rows = 0;
    Eigen::Index derived_end = 0;
    Eigen::Index built = 0;
    /// Takes other's state; of its FIFO and window, the held rows only (into these buffers when
    /// they are large enough, else into new ones without room).
    void assign_held(const Rows& other);
  };
  Rows now_;
  Rows undo_;  // now_ at mark(): the few held rows of the FIFO and window, which a push moves
};

}  // namespace dynid::ingest::detail
