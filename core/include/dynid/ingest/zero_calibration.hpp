#pragma once
// ZeroCalibration: sensor zeros from a tare recording, for the run that follows it.
//
// A test engineer zeroes a sensor where the physics gives a known zero: a wheel-torque meter
// with the car standing, clutch open or in neutral (the driveshafts carry nothing), a clamp-load
// sensor with the clutch fully open. The car records that tare (a second or more, announced and
// chunked like any run, same channels); ZeroCalibration takes its chunks and gives, per channel
// asked for, the mean of its valid raw samples (no filter: the true value is constant). apply()
// writes them into the run's announcement as the constant "<channel>_zero" of every model spec;
// the models that read it subtract it (longitudinal: wheel_torque_zero; clutch_slip:
// clutch_clamp_load_zero; see their headers for why an offset column does not do). Constants,
// not a new announcement field: the announcement's encoding, checksum and DDS type carry them
// already, and a model that does not read one ignores it.
//
// Why a tare, not stretches of the run itself: rows are folded as the run streams, so a zero
// must be known before the first row; and the run's own "zero" stretches are only nearly zero
// (with the clutch open during a shift the shafts still drive the input-side inertia).
//
// Contract: the constructor validates the tare's announcement and throws InputError for a
// channel it does not carry; push() validates each chunk (validate_chunk) and its sequence
// (consecutive from 0), InputError otherwise (no state changed); zeros() throws InputError
// naming a channel with fewer than min_samples valid samples (too short a tare to average the
// noise down).
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"

namespace dynid::ingest {

class ZeroCalibration {
 public:
  ZeroCalibration(RunAnnouncement tare, std::vector<std::string> channels, std::uint64_t min_samples = 50);

  void push(const Chunk& chunk);

  /// Channel -> mean of its valid samples in the tare.
  std::map<std::string, double> zeros() const;
  /// Sets constant "<channel>_zero" in every model spec of `run` (same vehicle as the tare).
  void apply(RunAnnouncement& run) const;

  std::uint64_t valid_samples() const { return count_; }

 private:
  RunAnnouncement tare_;
  std::vector<std::string> channels_;
  std::vector<std::size_t> columns_;
  std::vector<long double> sums_;
  std::uint64_t count_ = 0;
  std::uint64_t next_sequence_ = 0;
  std::uint64_t min_samples_;
};

}  // namespace dynid::ingest
