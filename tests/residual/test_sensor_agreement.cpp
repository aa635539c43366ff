// A better sensor judged against the published parameters with its offset as a nuisance
// (residual/sensor_agreement.hpp), on the project's simulated acceleration run through the
// product's data path. The accelerometer's offset is the rolling resistance's column in the
// longitudinal rows (the car never reverses): that parameter is left out by name, the others are
// compared. An accelerometer that agrees with the wheels up to its offset agrees; one that reads
// 10 % high moves the mass beyond the bound, and the statement names the mass.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "dynid/model/registry.hpp"
#include "dynid/residual/sensor_agreement.hpp"
#include "residual_test_support.hpp"
#include "sim_product_path.hpp"
#include "sim_test_support.hpp"

namespace dynid::residual {
namespace {

struct SimulatedRun {
  test::ProcessedRun processed;
  std::unique_ptr<model::Model> model;
};

SimulatedRun acceleration_run(std::uint64_t seed) {
  const sim::Run run = sim::test::run(sim::test::load_scenario_text("acceleration.toml"), seed);
  const ingest::ModelSpec spec = sim::test::model_spec("longitudinal_wheel", {}, {});
  SimulatedRun s{test::process(run, spec, /*tare=*/true), nullptr};
  s.model = model::make_model(spec.model, spec.constants);
  return s;
}

SensorAgreement agreement_on(const SimulatedRun& s,
                             const std::vector<ingest::PreprocessedSegment>& segments) {
  const ingest::RunAnnouncement& a = s.processed.announcement;
  return sensor_agreement(*s.model, {}, "road_grade_accelerometer", {"ax"}, segments,
                          a.sample_rate_hz, a.preprocessing.odmf, {}, a.preprocessing);
}

bool has(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// An accelerometer that reads the wheels' d_vx, plus an offset of 0.05 m/s^2 and noise of its own:
// the same signal up to its nuisance. (The simulated accelerometer is not: on this run the shafts'
// wind-up after each shift is in the wheels' rows and not in the body's acceleration.)
TEST(SensorAgreement, TheAccelerometersOffsetTakesTheRollingResistancesPlaceAndTheRestAgree) {
  const SimulatedRun s = acceleration_run(11);
  std::vector<ingest::PreprocessedSegment> same = s.processed.segments;
  std::mt19937_64 draw(5);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (ingest::PreprocessedSegment& segment : same) {
    Eigen::VectorXd ax = segment.channels["d_vx"].array() + 0.05;
    for (Eigen::Index k = 0; k < ax.size(); ++k) ax(k) += noise(draw);
    segment.channels.replace("ax", ax);
  }
  const SensorAgreement a = agreement_on(s, same);
  std::printf("%s\n", a.statement().c_str());
  EXPECT_EQ(a.offsets, std::vector<std::string>{"ax"});
  EXPECT_EQ(a.not_compared, std::vector<std::string>{"rolling_resistance"});
  ASSERT_EQ(a.compared.size(), 2u);
  EXPECT_EQ(a.compared[0].name, "mass");
  EXPECT_EQ(a.compared[1].name, "SCx");
  EXPECT_TRUE(a.agrees()) << a.statement();
  EXPECT_NE(a.statement().find("agrees with the published"), std::string::npos);
}

TEST(SensorAgreement, AnAccelerometerReadingTenPercentHighMovesTheMassBeyondTheBound) {
  const SimulatedRun s = acceleration_run(11);
  std::vector<ingest::PreprocessedSegment> scaled = s.processed.segments;
  for (ingest::PreprocessedSegment& segment : scaled)
    segment.channels.replace("ax", segment.channels["ax"] * 1.1);
  const SensorAgreement a = agreement_on(s, scaled);
  std::printf("%s\n", a.statement().c_str());
  EXPECT_FALSE(a.agrees());
  ASSERT_NE(a.largest(), nullptr);
  EXPECT_EQ(a.largest()->name, "mass");
  // Read through an accelerometer 10 % high, the mass is lower (by 6.6 % here: the other columns
  // take a part).
  EXPECT_LT(a.largest()->with_sensor / a.largest()->published, 0.95);
  EXPECT_NE(a.statement().find("differs from the published"), std::string::npos);
  EXPECT_TRUE(has(a.not_compared, "rolling_resistance"));
}

}  // namespace
}  // namespace dynid::residual
