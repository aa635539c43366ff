#include "dynid/car/live_merge.hpp"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <limits>
#include <thread>

namespace dynid::car {

LiveMerge::LiveMerge(CarPipeline& pipe, std::vector<FollowedSource> sources,
                     std::function<void(const std::string&)> on_stop)
    : pipe_(pipe),
      sources_(std::move(sources)),
      rows_(sources_.size()),
      late_(sources_.size(), 0),
      stop_told_(sources_.size(), false),
      on_stop_(std::move(on_stop)),
      let_in_until_(-std::numeric_limits<double>::infinity()),
      last_read_(-std::numeric_limits<double>::infinity()) {}

void LiveMerge::read_sources() {
  for (std::size_t s = 0; s < sources_.size(); ++s)
    for (auto& row : sources_[s].follower->poll()) {
      if (row.time <= let_in_until_) {  // the rows of its time are cut already
        for (double v : row.values) late_[s] += std::isfinite(v) ? 1 : 0;
        continue;
      }
      rows_[s].push_back(std::move(row));
    }
  for (std::size_t s = 0; s < sources_.size(); ++s)
    if (const auto& error = sources_[s].follower->error(); error && !stop_told_[s]) {
      stop_told_[s] = true;
      if (on_stop_) on_stop_("source '" + sources_[s].follower->name() + "' stopped, its channels missing from here on: " + *error);
    }
  stats_.late = 0;
  for (auto n : late_) stats_.late += n;
}

bool LiveMerge::may_go_in(double frame_time, double now) const {
  for (const auto& s : sources_)
    if (s.follower->complete_until() < frame_time && now < frame_time + s.wait) return false;
  return true;
}

// The samples of every source up to `time`, in a replay's order: by time, then source, then
// channel (auxiliary.cpp builds them source by source, channel by channel, and sorts stably).
void LiveMerge::give_samples_until(double time) {
  std::vector<AuxiliarySample> batch;
  for (std::size_t s = 0; s < sources_.size(); ++s) {
    auto& rows = rows_[s];
    std::size_t n = 0;
    while (n < rows.size() && rows[n].time <= time) ++n;
    for (std::size_t ci = 0; ci < sources_[s].column_of.size(); ++ci)
      for (std::size_t i = 0; i < n; ++i)
        if (std::isfinite(rows[i].values[ci])) batch.push_back({rows[i].time, sources_[s].column_of[ci], rows[i].values[ci]});
    rows.erase(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(n));
  }
  if (batch.empty()) return;
  std::stable_sort(batch.begin(), batch.end(),
                   [](const AuxiliarySample& a, const AuxiliarySample& b) { return a.time < b.time; });
  pipe_.append_auxiliary(std::move(batch));
}

void LiveMerge::let_in(const can::Frame& frame) {
  give_samples_until(frame.timestamp);
  pipe_.on_frame(frame);
  let_in_until_ = pipe_.newest_frame_time();  // a frame the pipeline refuses moves nothing
}

void LiveMerge::release(double now) {
  while (!held_.empty()) {
    const bool full = held_.size() > kMaxHeldFrames;
    if (!full && !may_go_in(held_.front().timestamp, now)) break;
    bool behind = false;
    for (const auto& s : sources_) behind = behind || s.follower->complete_until() < held_.front().timestamp;
    stats_.frames_forced += behind ? 1 : 0;
    let_in(held_.front());
    held_.pop_front();
  }
}

void LiveMerge::on_frame(const can::Frame& frame, double now) {
  if (sources_.empty()) {
    pipe_.on_frame(frame);
    return;
  }
  // What was read already may suffice: a source complete up to the frame's time has given
  // every row at or before it.
  if (held_.empty() && may_go_in(frame.timestamp, now)) {
    let_in(frame);
    return;
  }
  ++stats_.frames_held;
  held_.push_back(frame);
  if (now - last_read_ >= kReadInterval) {
    read_sources();
    last_read_ = now;
  }
  release(now);
}

void LiveMerge::service(double now) {
  if (sources_.empty()) return;
  read_sources();
  last_read_ = now;
  release(now);
}

void LiveMerge::idle(double now) {
  service(now);
  if (held_.empty()) pipe_.idle(now);
}

void LiveMerge::finish(const std::function<double()>& wall_clock) {
  read_sources();
  if (wall_clock && !held_.empty()) {
    const double last = held_.back().timestamp;
    double longest_wait = 0.0;  // bounds the wait whatever the frame's time says
    for (const auto& source : sources_) longest_wait = std::max(longest_wait, source.wait);
    const double deadline = wall_clock() + longest_wait;
    for (double now = wall_clock(); !may_go_in(last, now) && now < deadline; now = wall_clock()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      read_sources();
    }
  }
  release(std::numeric_limits<double>::infinity());
  give_samples_until(std::numeric_limits<double>::infinity());
  pipe_.finish();
}

std::vector<std::string> LiveMerge::report() const {
  std::vector<std::string> lines;
  for (std::size_t s = 0; s < sources_.size(); ++s) {
    const LiveSource& f = *sources_[s].follower;
    std::string line = "source '" + f.name() + "' (" + f.origin() + ", followed live): " +
                       std::to_string(f.rows()) + " rows";
    if (late_[s] > 0)
      line += "; " + std::to_string(late_[s]) + " samples came more than its wait (" + std::to_string(sources_[s].wait) +
              " s) after the bus and were dropped: raise [[sources]] wait";
    if (f.error()) line += "; stopped: " + *f.error();
    lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace dynid::car
