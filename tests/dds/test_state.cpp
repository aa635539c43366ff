// State topics (acks, estimates): reliable, transient-local, keep-last 1 per key, so a reader
// that joins late gets exactly the latest sample of every key, and keys do not mix.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <thread>

#include "dds_fixture.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/writer.hpp"
#include "dynid/ls/accumulator.hpp"

namespace dynid::dds {
namespace {

using namespace testing;

TEST(DdsState, LateJoiningReaderGetsTheLatestAckOfEveryRun) {
  Participant server(loopback_options());
  Writer<dynid_wire_ChunkAck> acks(server, {vehicle_partition("proto-17")});
  for (const std::int64_t highest : {-1, 3, 7})
    ASSERT_TRUE(acks.write(to_wire(ChunkReceipt{"proto-17", "run-1", highest,
                                                {{5, "checksum mismatch"}}}).data));
  ASSERT_TRUE(acks.write(to_wire(ChunkReceipt{"proto-17", "run-2", 1, {}}).data));

  // The car (re)starts after the acks were written.
  Participant car(loopback_options());
  Reader<dynid_wire_ChunkAck> reader(car, {vehicle_partition("proto-17")});
  auto received = take_count(reader, 2);
  ASSERT_EQ(received.size(), 2u);
  EXPECT_TRUE(reader.wait_take(300ms).empty()) << "more than one ack per run";
  std::map<std::string, ChunkReceipt> by_run;
  for (const auto& sample : received) {
    auto receipt = from_wire(sample.data);
    by_run[receipt.run] = receipt;
  }
  ASSERT_EQ(by_run.count("run-1"), 1u);
  ASSERT_EQ(by_run.count("run-2"), 1u);
  EXPECT_EQ(by_run["run-1"].highest_contiguous, 7);
  ASSERT_EQ(by_run["run-1"].rejections.size(), 1u);
  EXPECT_EQ(by_run["run-1"].rejections[0].sequence, 5u);
  EXPECT_EQ(by_run["run-1"].rejections[0].reason, "checksum mismatch");
  EXPECT_EQ(by_run["run-2"].highest_contiguous, 1);
}

EstimateTable table(const std::string& vehicle, const std::string& model, std::uint64_t revision,
                    double value) {
  EstimateTable t;
  t.vehicle = vehicle;
  t.model = model;
  t.source = "run-1";
  t.revision = revision;
  t.parameters = {{"m", "kg", value, 0.5, 100 * 0.5 / value, ls::ParameterStatus::kIdentified, "", ""}};
  t.groups = {{"longitudinal", 1000 * revision, 0.01}};
  return t;
}

TEST(DdsState, EstimatesKeepTheLatestPerVehicleAndModelWithoutCrosstalk) {
  Participant server(loopback_options());
  Participant watcher(loopback_options());
  Writer<dynid_wire_Estimate> vehicle_a(server, {vehicle_partition("A")});
  Writer<dynid_wire_Estimate> vehicle_b(server, {vehicle_partition("B")});
  // A reader present all along (it takes nothing meanwhile) keeps only the latest per key too.
  Reader<dynid_wire_Estimate> live(watcher, {kAllVehiclesPartition});
  ASSERT_TRUE(vehicle_a.wait_for_readers(1, kPatience));
  ASSERT_TRUE(vehicle_b.wait_for_readers(1, kPatience));
  // Value encodes (vehicle, model, revision): 1000 A / 2000 B, +100 per model, + revision.
  for (std::uint64_t revision = 1; revision <= 3; ++revision)
    ASSERT_TRUE(vehicle_a.write(to_wire(table("A", "lateral_bicycle", revision, 1000.0 + revision)).data));
  ASSERT_TRUE(vehicle_a.write(to_wire(table("A", "longitudinal", 1, 1101.0)).data));
  for (std::uint64_t revision = 1; revision <= 2; ++revision)
    ASSERT_TRUE(vehicle_b.write(to_wire(table("B", "lateral_bicycle", revision, 2000.0 + revision)).data));

  Participant engineer(loopback_options());
  Reader<dynid_wire_Estimate> late(engineer, {kAllVehiclesPartition});
  auto received = take_count(late, 3);
  ASSERT_EQ(received.size(), 3u);
  EXPECT_TRUE(late.wait_take(300ms).empty()) << "late joiner: more than one estimate per key";
  std::this_thread::sleep_for(200ms);  // every write has reached the live reader by now
  auto live_received = live.take();
  EXPECT_EQ(live_received.size(), 3u) << "live reader: more than one estimate per key";
  for (auto& sample : live_received) received.push_back(std::move(sample));

  std::map<std::pair<std::string, std::string>, EstimateTable> latest;
  for (const auto& sample : received) {
    auto t = from_wire(sample.data);
    // Both readers must agree: a second sample of a key must be the same latest one.
    const auto key = std::make_pair(t.vehicle, t.model);
    if (latest.count(key)) {
      EXPECT_EQ(latest[key].revision, t.revision) << t.vehicle << "/" << t.model;
    }
    latest[key] = t;
  }
  const auto expect = [&](const std::string& vehicle, const std::string& model,
                          std::uint64_t revision, double value) {
    const auto found = latest.find({vehicle, model});
    ASSERT_NE(found, latest.end()) << vehicle << "/" << model;
    EXPECT_EQ(found->second.revision, revision) << vehicle << "/" << model;
    ASSERT_EQ(found->second.parameters.size(), 1u);
    EXPECT_EQ(found->second.parameters[0].value, value) << vehicle << "/" << model;
    ASSERT_EQ(found->second.groups.size(), 1u);
    EXPECT_EQ(found->second.groups[0].rows, 1000 * revision);
  };
  expect("A", "lateral_bicycle", 3, 1003.0);
  expect("A", "longitudinal", 1, 1101.0);
  expect("B", "lateral_bicycle", 2, 2002.0);
}

TEST(DdsState, EstimateTableFromARealEstimateCarriesStatusesAndRelations) {
  // Column c = a + b: c is dependent, so a and b are regrouped with a relation naming c.
  Eigen::MatrixXd W(6, 3);
  W << 1, 0, 1, 0, 1, 1, 1, 1, 2, 2, 1, 3, 1, 3, 4, 3, 1, 4;
  const Eigen::VectorXd y = W * Eigen::Vector3d(1.0, 2.0, 3.0);
  ls::Accumulator accumulator(3);
  accumulator.fold(W, y);
  const auto estimate = ls::estimate(accumulator);
  const auto t = make_estimate_table("A", "toy", "run-1", {"a", "b", "c"}, {"kg", "N", "m"}, estimate);
  ASSERT_EQ(t.parameters.size(), 3u);
  EXPECT_EQ(t.parameters[0].status, ls::ParameterStatus::kRegrouped);
  EXPECT_EQ(t.parameters[2].status, ls::ParameterStatus::kDependent);
  EXPECT_NE(t.parameters[0].relation.find('c'), std::string::npos) << t.parameters[0].relation;
  EXPECT_TRUE(t.parameters[2].relation.empty());
  EXPECT_EQ(t.rows, 6u);
  // And it survives the wire shape unchanged.
  const auto back = from_wire(to_wire(t).data);
  EXPECT_EQ(back.parameters[0].relation, t.parameters[0].relation);
  EXPECT_EQ(back.parameters[2].status, ls::ParameterStatus::kDependent);
  EXPECT_THROW(make_estimate_table("A", "toy", "run-1", {"a", "b"}, {"kg", "N"}, estimate),
               InputError);
}

TEST(DdsState, ParameterStatusesReasonsAndTheModelNoteCrossTheWire) {
  // Issue 16: the statuses appended to the wire enum, each parameter's reason and the
  // model-level "not excited" line arrive as they were sent.
  EstimateTable t = table("A", "clutch_slip", 1, 0.2);
  const model::ModelVerdict verdict{
      {{ls::ParameterStatus::kNotExcited, "not excited: needs d_engine_speed (launches)"}},
      "needs d_engine_speed (launches)"};
  apply_verdict(t, verdict);
  for (const auto status : {ls::ParameterStatus::kPoorlyIdentified, ls::ParameterStatus::kNotExcited,
                            ls::ParameterStatus::kImplausible, ls::ParameterStatus::kIdentified}) {
    t.parameters[0].status = status;
    const auto back = from_wire(to_wire(t).data);
    EXPECT_EQ(back.parameters[0].status, status);
    EXPECT_EQ(back.parameters[0].reason, "not excited: needs d_engine_speed (launches)");
    EXPECT_EQ(back.not_excited, "needs d_engine_speed (launches)");
  }
  // The refined statuses travel as IDENTIFIED plus a verdict: a reader of the first release's
  // types (ParameterStatus unchanged) still reads them, as identified.
  t.parameters[0].status = ls::ParameterStatus::kNotExcited;
  const auto sample = to_wire(t);
  EXPECT_EQ(sample.data.parameters._buffer[0].status, dynid_wire_IDENTIFIED);
  EXPECT_EQ(sample.data.parameters._buffer[0].verdict, dynid_wire_NOT_EXCITED);
  t.parameters[0].status = ls::ParameterStatus::kRegrouped;
  EXPECT_EQ(to_wire(t).data.parameters._buffer[0].verdict, dynid_wire_NO_VERDICT);
  EXPECT_THROW(apply_verdict(t, model::ModelVerdict{}), InputError);
}

TEST(DdsState, TheEstimatorAndTheLeastSquaresValuesItReplacesCrossTheWire) {
  // Issue 16: where the bias test rejects least squares the rows carry IV's values and the
  // least-squares ones beside them; the table says whose values they are and why.
  EstimateTable t = table("A", "lateral_bicycle", 1, 3162.0);
  t.estimator = kInstrumentalVariables;
  t.bias_test = "least squares is biased by noise in the regressors (Durbin-Wu-Hausman p = 1e-06 < 0.01, 3 dof)";
  t.bias_through = 41;
  t.parameters[0].least_squares_value = 3101.5;
  t.parameters[0].least_squares_std = 4.25;
  auto back = from_wire(to_wire(t).data);
  EXPECT_EQ(back.estimator, kInstrumentalVariables);
  EXPECT_EQ(back.bias_test, t.bias_test);
  EXPECT_EQ(back.bias_through, 41u);
  EXPECT_EQ(back.parameters[0].value, 3162.0);
  EXPECT_EQ(back.parameters[0].least_squares_value, 3101.5);
  EXPECT_EQ(back.parameters[0].least_squares_std, 4.25);
  // An older server sends no estimator and zeros in the new members: least squares, and no
  // least-squares value that would read as a replaced one.
  auto older = to_wire(t);
  older.data.estimator[0] = '\0';
  older.data.parameters._buffer[0].least_squares_value = 0.0;
  older.data.parameters._buffer[0].least_squares_std = 0.0;
  back = from_wire(older.data);
  EXPECT_EQ(back.estimator, kLeastSquares);
  EXPECT_TRUE(std::isnan(back.parameters[0].least_squares_value));
  EXPECT_TRUE(std::isnan(back.parameters[0].least_squares_std));
  // SIMEX rows carry the least-squares value they replace in the same members.
  t.estimator = kSimex;
  back = from_wire(to_wire(t).data);
  EXPECT_EQ(back.estimator, kSimex);
  EXPECT_EQ(back.parameters[0].least_squares_value, 3101.5);
  EXPECT_EQ(back.parameters[0].least_squares_std, 4.25);
}

}  // namespace
}  // namespace dynid::dds
