#include "synthetic_body_run.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <numbers>

#include "dynid/error.hpp"
#include "dynid/model/body.hpp"

namespace dynid::load {

namespace {

constexpr std::array<const char*, 4> kCorners{"fl", "fr", "rl", "rr"};
constexpr std::array<const char*, 6> kWrench{"fx", "fy", "fz", "mx", "my", "mz"};
// Hub centres relative to the IMU point (m, body axes): a 2.6 m wheelbase, 1.6 m track.
constexpr std::array<std::array<double, 3>, 4> kHubs{
    {{1.2, 0.8, -0.3}, {1.2, -0.8, -0.3}, {-1.4, 0.8, -0.3}, {-1.4, -0.8, -0.3}}};

// One excitation: amplitude and the number of cycles per period (so the run is periodic).
struct Tone {
  double amplitude;
  int cycles;
};

// Per signal (ax ay az roll pitch yaw rate): three tones each, distinct cycle counts so the
// regressor's columns are independent; rates in rad/s, accelerations in m/s^2.
constexpr std::array<std::array<Tone, 3>, 6> kTones{{
    {{{1.5, 7}, {0.6, 23}, {0.3, 53}}},
    {{{2.0, 11}, {0.8, 29}, {0.3, 61}}},
    {{{0.8, 13}, {0.4, 31}, {0.2, 67}}},
    {{{0.10, 17}, {0.04, 37}, {0.02, 71}}},
    {{{0.08, 19}, {0.03, 41}, {0.02, 73}}},
    {{{0.30, 5}, {0.10, 43}, {0.05, 79}}},
}};

}  // namespace

Eigen::Matrix<double, 10, 1> SyntheticBodyRun::truth() {
  Eigen::Matrix<double, 10, 1> theta;
  theta << 550.0, 5.0, 40.0, 2100.0, 3.0, 2350.0, 60.0, -8.0, -300.0, 1500.0;
  return theta;
}

SyntheticBodyRun::SyntheticBodyRun(double sample_rate_hz, Eigen::Index chunk_rows, int odmf)
    : sample_rate_hz_(sample_rate_hz), chunk_rows_(chunk_rows), odmf_(odmf) {
  if (!(sample_rate_hz > 0.0)) throw InputError("load: the sample rate must be > 0 Hz");
  if (chunk_rows < 1) throw InputError("load: a chunk must have at least one row");
  const auto theta = truth();
  const Eigen::Vector3d p_fl(kHubs[0][0], kHubs[0][1], kHubs[0][2]);
  period_ = Eigen::MatrixXd::Zero(kPeriodSamples, 30);
  const double omega =
      2.0 * std::numbers::pi * sample_rate_hz / static_cast<double>(kPeriodSamples);
  for (Eigen::Index i = 0; i < kPeriodSamples; ++i) {
    const double t = static_cast<double>(i) / sample_rate_hz;
    std::array<double, 6> value{}, slope{};
    for (std::size_t s = 0; s < kTones.size(); ++s)
      for (const Tone& tone : kTones[s]) {
        const double w = omega * tone.cycles;
        value[s] += tone.amplitude * std::sin(w * t);
        slope[s] += tone.amplitude * w * std::cos(w * t);
      }
    value[2] += 9.81;  // the accelerometer's specific force holds gravity
    const Eigen::Vector3d a(value[0], value[1], value[2]);
    const Eigen::Vector3d w(value[3], value[4], value[5]);
    const Eigen::Vector3d dw(slope[3], slope[4], slope[5]);
    const Eigen::Matrix<double, 6, 1> wrench = model::BodyModel::regressor(a, w, dw) * theta;
    const Eigen::Vector3d force = wrench.head<3>();
    const Eigen::Vector3d moment = wrench.tail<3>() - p_fl.cross(force);
    for (int s = 0; s < 6; ++s) period_(i, s) = value[static_cast<std::size_t>(s)];
    period_.block<1, 3>(i, 6) = force.transpose();  // hub fl: fx fy fz, then mx my mz
    period_.block<1, 3>(i, 9) = moment.transpose();
  }
}

ingest::RunAnnouncement SyntheticBodyRun::announcement(const std::string& vehicle,
                                                       const std::string& run) const {
  ingest::RunAnnouncement a;
  a.vehicle = vehicle;
  a.run = run;
  a.sample_rate_hz = sample_rate_hz_;
  a.channels = {{"ax", "m/s^2"},        {"ay", "m/s^2"},         {"az", "m/s^2"},
                {"roll_rate", "rad/s"}, {"pitch_rate", "rad/s"}, {"yaw_rate", "rad/s"}};
  for (const char* corner : kCorners)
    for (std::size_t j = 0; j < kWrench.size(); ++j)
      a.channels.push_back({std::string("hub_") + kWrench[j] + "_" + corner, j < 3 ? "N" : "N m"});
  ingest::ModelSpec body{"body", {}, {}};
  for (std::size_t c = 0; c < kCorners.size(); ++c)
    for (std::size_t axis = 0; axis < 3; ++axis)
      body.constants[std::string("hub_") + "xyz"[axis] + "_" + kCorners[c]] = kHubs[c][axis];
  a.models.push_back(std::move(body));
  a.preprocessing.odmf = odmf_;
  return a;
}

ingest::Chunk SyntheticBodyRun::chunk(const std::string& vehicle, const std::string& run,
                                      std::uint64_t sequence) const {
  ingest::Chunk c;
  c.vehicle = vehicle;
  c.run = run;
  c.sequence = sequence;
  c.first_sample_index = sequence * static_cast<std::uint64_t>(chunk_rows_);
  c.samples.resize(chunk_rows_, period_.cols());
  for (Eigen::Index r = 0; r < chunk_rows_; ++r) {
    const auto index = (c.first_sample_index + static_cast<std::uint64_t>(r)) %
                       static_cast<std::uint64_t>(kPeriodSamples);
    c.samples.row(r) = period_.row(static_cast<Eigen::Index>(index));
  }
  c.valid.assign(static_cast<std::size_t>(chunk_rows_), 1);
  c.seal();
  return c;
}

}  // namespace dynid::load
