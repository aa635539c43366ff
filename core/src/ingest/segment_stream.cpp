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
// has room for these rows only (an undo copy needs no room to grow).
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
    now_.derivative.emplace(static_cast<Eigen::Index>(layout_.derived_from.size()), sample_period);
  // No rows yet: a run that has not sent a sample costs no buffer (they grow on first use).
  now_.fifo.resize(0, static_cast<Eigen::Index>(layout_.unfiltered.size()));
  now_.window.resize(0, layout_.width());
}

void SegmentStream::Rows::assign_held(const Rows& other) {
  derivative = other.derivative;
  active = other.active;
  start = other.start;
  copy_rows(fifo, other.fifo, other.fifo_rows);
  fifo_rows = other.fifo_rows;
  copy_rows(window, other.window, other.window_rows);
  window_first = other.window_first;
  window_rows = other.window_rows;
  derived_end = other.derived_end;
  built = other.built;
}

void SegmentStream::mark() {
  filter_.mark();
  undo_.assign_held(now_);
}

void SegmentStream::rollback() {
  filter_.rollback();
  now_.assign_held(undo_);
}

void SegmentStream::commit() {
  filter_.commit();
  // Between pushes the window holds a few rows of context: no room kept for the next push.
  if (now_.window.rows() > now_.window_rows)
    now_.window.conservativeResize(now_.window_rows, Eigen::NoChange);
}

void SegmentStream::start(std::uint64_t start) {
  filter_.reset();
  if (now_.derivative) now_.derivative->reset();
  now_.active = true;
  now_.start = start;
  now_.fifo_rows = 0;
  now_.window_first = now_.window_rows = now_.derived_end = now_.built = 0;
}

void SegmentStream::push(const Eigen::Ref<const Eigen::MatrixXd>& raw) {
  const Eigen::Index m = raw.rows();
  if (now_.fifo.rows() < now_.fifo_rows + m)
    now_.fifo.conservativeResize(std::max(2 * now_.fifo.rows(), now_.fifo_rows + m),
                                 Eigen::NoChange);
  for (std::size_t i = 0; i < layout_.unfiltered.size(); ++i)
    now_.fifo.col(static_cast<Eigen::Index>(i)).segment(now_.fifo_rows, m) =
        raw.col(layout_.unfiltered[i]);
  now_.fifo_rows += m;
  append_final(filter_.push(gather(raw, layout_.filtered)));
}

void SegmentStream::finish() {
  append_final(filter_.finish());
  if (!now_.derivative) return;
  const Eigen::MatrixXd last = now_.derivative->finish();  // the last one or two samples'
  now_.window.block(now_.derived_end - now_.window_first, layout_.announced, last.rows(), last.cols()) = last;
  now_.derived_end += last.rows();
}

void SegmentStream::append_final(const Eigen::MatrixXd& filtered) {
  const Eigen::Index r = filtered.rows();
  if (r == 0) return;
  reserve_window(now_.window_rows + r);
  const Eigen::Index base = now_.window_rows;
  for (std::size_t i = 0; i < layout_.filtered.size(); ++i)
    now_.window.col(layout_.filtered[i]).segment(base, r) =
        filtered.col(static_cast<Eigen::Index>(i));
  // The pass-through channels of the same samples: the oldest r of the FIFO.
  for (std::size_t i = 0; i < layout_.unfiltered.size(); ++i)
    now_.window.col(layout_.unfiltered[i]).segment(base, r) =
        now_.fifo.col(static_cast<Eigen::Index>(i)).head(r);
  now_.fifo.topRows(now_.fifo_rows - r) = now_.fifo.middleRows(r, now_.fifo_rows - r).eval();
  now_.fifo_rows -= r;
  // Derived columns are filled as the derivative releases them; defined until then.
  now_.window.block(base, layout_.announced, r, now_.window.cols() - layout_.announced).setZero();
  now_.window_rows += r;
  if (!now_.derivative) {
    now_.derived_end = now_.window_first + now_.window_rows;
    return;
  }
  const Eigen::MatrixXd d =
      now_.derivative->push(gather(now_.window.middleRows(base, r), layout_.derived_from));
  now_.window.block(now_.derived_end - now_.window_first, layout_.announced, d.rows(), d.cols()) =
      d;
  now_.derived_end += d.rows();
}

void SegmentStream::reserve_window(Eigen::Index rows) {
  if (now_.window.rows() < rows)
    now_.window.conservativeResize(std::max({2 * now_.window.rows(), rows, usual_window()}),
                                   Eigen::NoChange);
}

ReadyRows SegmentStream::ready(bool at_end) const {
  const Eigen::Index ready_end =
      at_end ? now_.derived_end : std::max(now_.built, now_.derived_end - reach_.ahead);
  const Eigen::Index context = std::max(now_.window_first, now_.built - reach_.back);
  const Eigen::MatrixXd& w = now_.window;
  return {w.middleRows(context - now_.window_first, now_.derived_end - context),
          now_.built - context, ready_end - now_.built, context};
}

void SegmentStream::consume(Eigen::Index count) {
  now_.built += count;
  const Eigen::Index drop = std::max<Eigen::Index>(0, now_.built - reach_.back - now_.window_first);
  if (drop == 0) return;
  const Eigen::Index keep = now_.window_rows - drop;
  now_.window.topRows(keep) = now_.window.middleRows(drop, keep).eval();
  now_.window_first += drop;
  now_.window_rows = keep;
}

void SegmentStream::held_buffers(const std::string& prefix,
                                 std::vector<signal::HeldBuffer>& out) const {
  for (signal::HeldBuffer& b : filter_.held_buffers()) {
    b.name = prefix + b.name;
    out.push_back(std::move(b));
  }
  if (now_.derivative) {
    const Eigen::MatrixXd recent = now_.derivative->state().recent;
    out.push_back(signal::held_buffer(prefix + "derivative recent", recent, recent.rows()));
  }
  out.push_back(signal::held_buffer(prefix + "pass-through FIFO", now_.fifo, now_.fifo_rows));
  out.push_back(signal::held_buffer(prefix + "row window", now_.window, now_.window_rows));
  out.push_back(signal::held_buffer(prefix + "undo FIFO", undo_.fifo, undo_.fifo_rows));
  out.push_back(signal::held_buffer(prefix + "undo window", undo_.window, undo_.window_rows));
}

void SegmentStream::save(ByteWriter& w) const {
  w.put_bool(now_.active);
  w.put<std::uint64_t>(now_.start);
  const signal::StreamingZeroPhaseFilter::State f = filter_.state();
  put_index(w, f.samples_in);
  put_index(w, f.samples_out);
  w.put_bool(f.finished);
  w.put_matrix(f.head);
  w.put_matrix(f.raw_tail);
  w.put_matrix(f.forward_state);
  w.put_matrix(f.pending);
  if (now_.derivative) {
    const signal::StreamingDerivative::State d = now_.derivative->state();
    put_index(w, d.samples_in);
    put_index(w, d.samples_out);
    w.put_bool(d.finished);
    w.put_matrix(d.recent);
  }
  w.put_matrix(now_.fifo.topRows(now_.fifo_rows));
  w.put_matrix(now_.window.topRows(now_.window_rows));
  put_index(w, now_.window_first);
  put_index(w, now_.derived_end);
  put_index(w, now_.built);
}

void SegmentStream::load(ByteReader& r) {
  now_.active = r.get_bool("segment active");
  now_.start = r.get<std::uint64_t>("segment start");
  signal::StreamingZeroPhaseFilter::State f;
  f.samples_in = get_index(r, "filter samples in");
  f.samples_out = get_index(r, "filter samples out");
  f.finished = r.get_bool("filter finished");
  f.head = r.get_matrix("filter head");
  f.raw_tail = r.get_matrix("filter raw tail");
  f.forward_state = r.get_matrix("filter forward state");
  f.pending = r.get_matrix("filter pending");
  filter_.restore(f);
  if (now_.derivative) {
    signal::StreamingDerivative::State d;
    d.samples_in = get_index(r, "derivative samples in");
    d.samples_out = get_index(r, "derivative samples out");
    d.finished = r.get_bool("derivative finished");
    d.recent = r.get_matrix("derivative recent");
    now_.derivative->restore(d);
  }
  now_.fifo = r.get_matrix("pass-through FIFO");
  now_.fifo_rows = now_.fifo.rows();
  now_.window = r.get_matrix("row window");
  now_.window_rows = now_.window.rows();
  now_.window_first = get_index(r, "window first");
  now_.derived_end = get_index(r, "derived end");
  now_.built = get_index(r, "built");
  const Eigen::Index window_end = now_.window_first + now_.window_rows;
  const Eigen::Index derived = now_.derivative ? now_.derivative->samples_out() : window_end;
  const bool fits = now_.fifo.cols() == static_cast<Eigen::Index>(layout_.unfiltered.size()) &&
                    now_.fifo_rows == filter_.samples_in() - filter_.samples_out() &&
                    now_.window.cols() == layout_.width() && window_end == filter_.samples_out() &&
                    (!now_.derivative || now_.derivative->samples_in() == window_end) &&
                    now_.derived_end == derived &&
                    now_.window_first <= std::max<Eigen::Index>(0, now_.built - reach_.back) &&
                    now_.built <= now_.derived_end && now_.fifo.allFinite() &&
                    now_.window.allFinite();
  if (!fits) r.fail("segment buffers do not fit the run's layout or each other");
  reserve_window(usual_window());
}

Eigen::Index SegmentStream::usual_window() const {
  // A push adds what the filter releases to the context: a block at least (more for a longer
  // chunk, the window then grows to it; commit() gives the room back).
  return filter_.block() + reach_.back + reach_.ahead;
}

}  // namespace dynid::ingest::detail
