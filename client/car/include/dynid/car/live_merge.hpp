#pragma once
// LiveMerge: the live bus and the auxiliary sources followed beside it (live_source.hpp)
// into one CarPipeline, so that a live run cuts the chunks a replay of the same frames and the
// same source files cuts (pipeline.hpp merges whole sources there), as long as every source keeps
// up with the bus within its wait.
//
// Why hold the bus: the pipeline merges, before each frame, every auxiliary sample up to the
// frame's time. A writer's rows reach us later than the frames of the same instant (a logger
// writes in blocks, a pipe buffers), so a frame at bus time t is held until every source has been
// read up to t (LiveSource::complete_until), or until `now` (the wall clock, which is the
// live bus's clock) passes t + that source's wait ([[sources]] wait, VehicleProfile). A held
// frame then goes in with the source's samples up to its time, in the order a replay gives them
// (time, then source, then channel). A row of a source that arrives after the bus was let past
// its time cannot join the rows already cut: it is dropped and counted (late), and the log
// says which wait to raise. Held frames are bounded by the waits (and kMaxHeldFrames).
//
// Contract: on_frame() and service() in the live loop's order; idle() when the bus is silent;
// finish() once, which lets the sources catch up with the last frames (within their waits), lets
// everything in and finishes the pipeline. With no source it passes every frame straight through.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <dynid/can/frame.hpp>

#include "dynid/car/auxiliary_follower.hpp"
#include "dynid/car/pipeline.hpp"

namespace dynid::car {

struct LiveMergeStats {
  std::uint64_t frames_held = 0;    ///< frames that had to wait for a source
  std::uint64_t frames_forced = 0;  ///< frames let in at a wait's end, a source behind them
  std::uint64_t late = 0;           ///< auxiliary samples dropped: they came after the bus passed their time
};

class LiveMerge {
 public:
  static constexpr std::size_t kMaxHeldFrames = 1u << 20;
  /// Seconds of wall clock between two reads of the sources while frames arrive: a read per
  /// frame (a system call per source) made a slow reader fall behind a busy bus (kernel drops
  /// under ASan in the VM test); 5 ms is a fraction of a grid period.
  static constexpr double kReadInterval = 0.005;

  /// `on_stop` hears at once of a source that stopped (its error), so a live user sees it.
  LiveMerge(CarPipeline& pipe, std::vector<FollowedSource> sources,
            std::function<void(const std::string&)> on_stop = {});

  /// A frame of the bus (its timestamp on the wall clock), at wall time `now`.
  void on_frame(const can::Frame& frame, double now);
  /// Reads the sources and lets in what may go in at wall time `now`.
  void service(double now);
  /// No frame for a while: as service(), and the pipeline's clock moves once nothing is held.
  void idle(double now);
  /// The bus has ended. With `wall_clock`, first waits (polling the sources) until each has
  /// been read up to the newest frame or its wait has passed, as on_frame would have; then lets
  /// everything in and finishes the pipeline.
  void finish(const std::function<double()>& wall_clock = {});

  const LiveMergeStats& stats() const { return stats_; }
  const std::vector<FollowedSource>& sources() const { return sources_; }
  /// One line per source (rows, late samples, its error if it stopped), for the run's log.
  std::vector<std::string> report() const;

 private:
  struct Pending {
    std::size_t source;
    AuxiliaryRow row;
  };

  CarPipeline& pipe_;
  std::vector<FollowedSource> sources_;
  std::vector<std::deque<AuxiliaryRow>> rows_;  // per source, read, not yet given to the pipeline
  std::vector<std::uint64_t> late_;             // per source
  std::vector<bool> stop_told_;                 // per source
  std::function<void(const std::string&)> on_stop_;
  std::deque<can::Frame> held_;
  double let_in_until_;  // newest time of a frame given to the pipeline
  double last_read_;     // wall time of the last read of the sources
  LiveMergeStats stats_;

  void read_sources();
  bool may_go_in(double frame_time, double now) const;
  void let_in(const can::Frame& frame);
  void give_samples_until(double time);
  void release(double now);
};

}  // namespace dynid::car
