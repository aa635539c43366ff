// ZeroCalibration: a tare's chunks -> sensor zeros -> "<channel>_zero" constants of a run's
// model specs (ingest/zero_calibration.hpp).
#include <gtest/gtest.h>

#include "dynid/error.hpp"
#include "dynid/ingest/zero_calibration.hpp"
#include "ingest_test_support.hpp"

namespace dynid::ingest::test {
namespace {

Chunk tare_chunk(const RunAnnouncement& a, std::uint64_t sequence, Eigen::Index rows, double torque) {
  Chunk c;
  c.vehicle = a.vehicle;
  c.run = a.run;
  c.sequence = sequence;
  c.first_sample_index = sequence * static_cast<std::uint64_t>(rows);
  c.samples = Eigen::MatrixXd::Zero(rows, static_cast<Eigen::Index>(a.channels.size()));
  c.samples.col(static_cast<Eigen::Index>(a.column_of("wheel_torque"))).setConstant(torque);
  c.valid.assign(static_cast<std::size_t>(rows), 1);
  c.seal();
  return c;
}

TEST(ZeroCalibration, MeanOfValidSamplesBecomesEveryModelsConstant) {
  RunAnnouncement tare = announcement_for(Truth{});
  tare.run = "tare-0042";
  ZeroCalibration zero(tare, {"wheel_torque", "ax"}, 50);
  zero.push(tare_chunk(tare, 0, 40, 6.0));
  Chunk second = tare_chunk(tare, 1, 40, 8.0);
  // A gap: its (finite) values must not count.
  second.valid[5] = 0;
  second.samples(5, static_cast<Eigen::Index>(tare.column_of("wheel_torque"))) = 1e6;
  second.seal();
  zero.push(second);
  EXPECT_EQ(zero.valid_samples(), 79U);
  const auto z = zero.zeros();
  EXPECT_DOUBLE_EQ(z.at("wheel_torque"), (40 * 6.0 + 39 * 8.0) / 79.0);
  EXPECT_DOUBLE_EQ(z.at("ax"), 0.0);

  RunAnnouncement run = announcement_for(Truth{});
  zero.apply(run);
  for (const auto& m : run.models) {
    EXPECT_DOUBLE_EQ(m.constants.at("wheel_torque_zero"), z.at("wheel_torque")) << m.model;
    EXPECT_DOUBLE_EQ(m.constants.at("ax_zero"), 0.0) << m.model;
  }
  EXPECT_NO_THROW(run.validate());
}

TEST(ZeroCalibration, RejectsUnknownChannelsWrongSequencesShortTaresAndOtherVehicles) {
  const RunAnnouncement tare = announcement_for(Truth{});
  EXPECT_THROW(ZeroCalibration(tare, {"clutch_clamp_load"}), InputError);
  ZeroCalibration zero(tare, {"wheel_torque"}, 50);
  EXPECT_THROW(zero.push(tare_chunk(tare, 1, 40, 6.0)), InputError);  // #0 expected
  Chunk bad = tare_chunk(tare, 0, 40, 6.0);
  bad.checksum ^= 1U;
  EXPECT_THROW(zero.push(bad), InputError);
  zero.push(tare_chunk(tare, 0, 40, 6.0));
  EXPECT_THROW(static_cast<void>(zero.zeros()), InputError);  // 40 < 50 samples
  zero.push(tare_chunk(tare, 1, 40, 6.0));
  RunAnnouncement other = announcement_for(Truth{});
  other.vehicle = "proto-18";
  EXPECT_THROW(zero.apply(other), InputError);
}

}  // namespace
}  // namespace dynid::ingest::test
