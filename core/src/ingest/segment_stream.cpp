#include "segment_stream.hpp"

#include <algorithm>
#include <string>

#include "dynid/ingest/run_processor.hpp"

namespace dynid::ingest::detail {
namespace {

Eigen::MatrixXd gather(const Eigen::Ref<const Eigen::MatrixXd>& x,
                       const std::vector<Eigen::Index>& columns) {
  Eigen::MatrixXd out(x.rows(), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t i = 0; i < columns.size(); ++i)
    out.col(static_cast<Eigen::Index>(i)) = x.col(columns[i]);
  return out;
}

// dst's first `rows` rows = src's, keeping dst's buffer when it is large enough; a new buffer
// has room for these rows only (a rollback copy needs no room to grow).
void copy_rows(Eigen::MatrixXd& dst, const Eigen::MatrixXd& src, Eigen::Index rows) {
  if (dst.cols() != src.cols() || dst.rows() < rows) dst.resize(rows, src.cols());
  dst.topRows(rows) = src.topRows(rows);
}

void put_index(ByteWriter& w, Eigen::Index v) {
  w.put<std::int64_t>(v);
}
Eigen::Index get_index(ByteReader& r, const char* field) {
  const auto v = r.get<std::int64_t>(field);
  if (v < 0) r.fail(std::string(field) + " is negative");
  return static_cast<Eigen::Index>(v);
}

}  // namespace

SegmentStream::SegmentStream(const signal::Sos& sos, Layout layout, double sample_period,
                             double tolerance, model::RowReach reach)
    : layout_(std::move(layout)),
      reach_{std::max(reach.back, kReachBack), std::max(reach.ahead, kReachAhead)},
      filter_(sos, static_cast<Eigen::Index>(layout_.filtered.size()), tolerance) {
  if (!layout_.derived_from.empty())
    derivative_.emplace(static_cast<Eigen::Index>(layout_.derived_from.size()), sample_period);
  // No rows yet: a run that has not sent a sample costs no buffer (they grow on first use).
  fifo_.resize(0, static_cast<Eigen::Index>(layout_.unfiltered.size()));
  window_.resize(0, layout_.width());
}

SegmentStream::SegmentStream(const SegmentStream& other)
    : layout_(other.layout_), reach_(other.reach_), filter_(other.filter_) {
  *this = other;
}

SegmentStream& SegmentStream::operator=(const SegmentStream& other) {
  if (this == &other) return *this;
  layout_ = other.layout_;
  reach_ = other.reach_;
  filter_ = other.filter_;
  derivative_ = other.derivative_;
  active_ = other.active_;
  start_ = other.start_;
  copy_rows(fifo_, other.fifo_, other.fifo_rows_);
  fifo_rows_ = other.fifo_rows_;
  copy_rows(window_, other.window_, other.window_rows_);
  window_first_ = other.window_first_;
  window_rows_ = other.window_rows_;
  derived_end_ = other.derived_end_;
  built_ = other.built_;
  return *this;
}

void SegmentStream::start(std::uint64_t start) {
  filter_.reset();
  if (derivative_) derivative_->reset();
  active_ = true;
  start_ = start;
  fifo_rows_ = 0;
  window_first_ = window_rows_ = derived_end_ = built_ = 0;
}

void SegmentStream::push(const Eigen::Ref<const Eigen::MatrixXd>& raw) {
  const Eigen::Index m = raw.rows();
  if (fifo_.rows() < fifo_rows_ + m)
    fifo_.conservativeResize(std::max(2 * fifo_.rows(), fifo_rows_ + m), Eigen::NoChange);
  for (std::size_t i = 0; i < layout_.unfiltered.size(); ++i)
    fifo_.col(static_cast<Eigen::Index>(i)).segment(fifo_rows_, m) = raw.col(layout_.unfiltered[i]);
  fifo_rows_ += m;
  append_final(filter_.push(gather(raw, layout_.filtered)));
}

void SegmentStream::finish() {
  append_final(filter_.finish());
  if (!derivative_) return;
  const Eigen::MatrixXd last = derivative_->finish();
  window_.row(derived_end_ - window_first_).tail(last.cols()) = last.row(0);
  ++derived_end_;
}

void SegmentStream::append_final(const Eigen::MatrixXd& filtered) {
  const Eigen::Index r = filtered.rows();
  if (r == 0) return;
  reserve_window(window_rows_ + r);
  const Eigen::Index base = window_rows_;
  for (std::size_t i = 0; i < layout_.filtered.size(); ++i)
    window_.col(layout_.filtered[i]).segment(base, r) = filtered.col(static_cast<Eigen::Index>(i));
  // The pass-through channels of the same samples: the oldest r of the FIFO.
  for (std::size_t i = 0; i < layout_.unfiltered.size(); ++i)
    window_.col(layout_.unfiltered[i]).segment(base, r) =
        fifo_.col(static_cast<Eigen::Index>(i)).head(r);
  fifo_.topRows(fifo_rows_ - r) = fifo_.middleRows(r, fifo_rows_ - r).eval();
  fifo_rows_ -= r;
  // Derived columns are filled as the derivative releases them; defined until then.
  window_.block(base, layout_.announced, r, window_.cols() - layout_.announced).setZero();
  window_rows_ += r;
  if (!derivative_) {
    derived_end_ = window_first_ + window_rows_;
    return;
  }
  const Eigen::MatrixXd d =
      derivative_->push(gather(window_.middleRows(base, r), layout_.derived_from));
  window_.block(derived_end_ - window_first_, layout_.announced, d.rows(), d.cols()) = d;
  derived_end_ += d.rows();
}

void SegmentStream::reserve_window(Eigen::Index rows) {
  if (window_.rows() < rows)
    window_.conservativeResize(std::max({2 * window_.rows(), rows, usual_window()}),
                               Eigen::NoChange);
}

ReadyRows SegmentStream::ready(bool at_end) const {
  const Eigen::Index ready_end =
      at_end ? derived_end_ : std::max(built_, derived_end_ - reach_.ahead);
  const Eigen::Index context = std::max(window_first_, built_ - reach_.back);
  const Eigen::MatrixXd& w = window_;
  return {w.middleRows(context - window_first_, derived_end_ - context), built_ - context,
          ready_end - built_, context};
}

void SegmentStream::consume(Eigen::Index count) {
  built_ += count;
  const Eigen::Index drop = std::max<Eigen::Index>(0, built_ - reach_.back - window_first_);
  if (drop == 0) return;
  const Eigen::Index used = window_rows_;
  const Eigen::Index keep = window_rows_ - drop;
  window_.topRows(keep) = window_.middleRows(drop, keep).eval();
  window_first_ += drop;
  window_rows_ = keep;
  // A chunk much longer than this one grew the window: give the memory back so idle runs stay
  // small (room for what this one used stays: chunks of one size do not reallocate).
  const Eigen::Index usual = std::max(usual_window(), used);
  if (window_.rows() > 4 * usual) window_.conservativeResize(usual, Eigen::NoChange);
}

void SegmentStream::held_buffers(const std::string& prefix,
                                 std::vector<signal::HeldBuffer>& out) const {
  for (signal::HeldBuffer& b : filter_.held_buffers()) {
    b.name = prefix + b.name;
    out.push_back(std::move(b));
  }
  if (derivative_) {
    const Eigen::MatrixXd recent = derivative_->state().recent;
    out.push_back(signal::held_buffer(prefix + "derivative recent", recent, recent.rows()));
  }
  out.push_back(signal::held_buffer(prefix + "pass-through FIFO", fifo_, fifo_rows_));
  out.push_back(signal::held_buffer(prefix + "row window", window_, window_rows_));
}

void SegmentStream::save(ByteWriter& w) const {
  w.put_bool(active_);
  w.put<std::uint64_t>(start_);
  const signal::StreamingZeroPhaseFilter::State f = filter_.state();
  put_index(w, f.samples_in);
  put_index(w, f.samples_out);
  w.put_bool(f.finished);
  w.put_matrix(f.head);
  w.put_matrix(f.raw_tail);
  w.put_matrix(f.forward_state);
  w.put_matrix(f.pending);
  if (derivative_) {
    const signal::StreamingDerivative::State d = derivative_->state();
    put_index(w, d.samples_in);
    put_index(w, d.samples_out);
    w.put_bool(d.finished);
    w.put_matrix(d.recent);
  }
  w.put_matrix(fifo_.topRows(fifo_rows_));
  w.put_matrix(window_.topRows(window_rows_));
  put_index(w, window_first_);
  put_index(w, derived_end_);
  put_index(w, built_);
}

void SegmentStream::load(ByteReader& r) {
  active_ = r.get_bool("segment active");
  start_ = r.get<std::uint64_t>("segment start");
  signal::StreamingZeroPhaseFilter::State f;
  f.samples_in = get_index(r, "filter samples in");
  f.samples_out = get_index(r, "filter samples out");
  f.finished = r.get_bool("filter finished");
  f.head = r.get_matrix("filter head");
  f.raw_tail = r.get_matrix("filter raw tail");
  f.forward_state = r.get_matrix("filter forward state");
  f.pending = r.get_matrix("filter pending");
  filter_.restore(f);
  if (derivative_) {
    signal::StreamingDerivative::State d;
    d.samples_in = get_index(r, "derivative samples in");
    d.samples_out = get_index(r, "derivative samples out");
    d.finished = r.get_bool("derivative finished");
    d.recent = r.get_matrix("derivative recent");
    derivative_->restore(d);
  }
  fifo_ = r.get_matrix("pass-through FIFO");
  fifo_rows_ = fifo_.rows();
  window_ = r.get_matrix("row window");
  window_rows_ = window_.rows();
  window_first_ = get_index(r, "window first");
  derived_end_ = get_index(r, "derived end");
  built_ = get_index(r, "built");
  const Eigen::Index window_end = window_first_ + window_rows_;
  const Eigen::Index derived = derivative_ ? derivative_->samples_out() : window_end;
  const bool fits = fifo_.cols() == static_cast<Eigen::Index>(layout_.unfiltered.size()) &&
                    fifo_rows_ == filter_.samples_in() - filter_.samples_out() &&
                    window_.cols() == layout_.width() && window_end == filter_.samples_out() &&
                    (!derivative_ || derivative_->samples_in() == window_end) &&
                    derived_end_ == derived &&
                    window_first_ <= std::max<Eigen::Index>(0, built_ - reach_.back) &&
                    built_ <= derived_end_ && fifo_.allFinite() && window_.allFinite();
  if (!fits) r.fail("segment buffers do not fit the run's layout or each other");
  reserve_window(usual_window());
}

Eigen::Index SegmentStream::usual_window() const {
  // Between pushes the window holds the context only; a push adds what the filter releases (a
  // block at least; more for a longer chunk, the window then grows to it).
  return filter_.block() + reach_.back + reach_.ahead;
}

}  // namespace dynid::ingest::detail
