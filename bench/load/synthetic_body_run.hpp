#pragma once
// SyntheticBodyRun: the load benchmark's vehicle data. A run announcing the `body` model
// (model/body.hpp: 10 parameters [XX XY XZ YY YZ ZZ MX MY MZ M]) over its 30 measured channels
// (ax ay az, roll/pitch/yaw rate, and the 6 wrench components of the 4 hubs), with samples made
// exactly from that model and known parameters, so the server's rows are real rows of a
// well-posed identification, not noise.
//
// Signals: the IMU channels are sums of sines whose periods divide `period_samples`, so the
// run is periodic and any number of chunks can be cut without storing the run; the wrench is
// the regressor (with the analytic rate derivatives) times the true parameters, all of it
// applied at the front-left hub (hub moment = N - p_fl x F), the other hubs carrying zero.
//
// Contract: announcement() is valid (RunAnnouncement::validate) for any non-empty ids and
// a positive `sample_rate_hz`; chunk(k) is the sealed chunk k of `chunk_rows` rows (grid
// indices k*chunk_rows ..), all rows valid. The constructor throws InputError for
// chunk_rows < 1 or sample_rate_hz <= 0.
#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"

namespace dynid::load {

class SyntheticBodyRun {
 public:
  static constexpr Eigen::Index kPeriodSamples = 6400;  // 64 s at 100 Hz

  SyntheticBodyRun(double sample_rate_hz, Eigen::Index chunk_rows, int odmf);

  ingest::RunAnnouncement announcement(const std::string& vehicle, const std::string& run) const;
  /// Chunk `sequence` of `vehicle`/`run`, sealed.
  ingest::Chunk chunk(const std::string& vehicle, const std::string& run,
                      std::uint64_t sequence) const;

  Eigen::Index chunk_rows() const { return chunk_rows_; }
  Eigen::Index channels() const { return period_.cols(); }
  /// The parameters the samples are made from, in the model's order.
  static Eigen::Matrix<double, 10, 1> truth();

 private:
  double sample_rate_hz_;
  Eigen::Index chunk_rows_;
  int odmf_;
  Eigen::MatrixXd period_;  // kPeriodSamples x 30: one period of the run
};

}  // namespace dynid::load
