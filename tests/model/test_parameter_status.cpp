// Parameter status (model/parameter_status.hpp, issue 16): each rule on a hand-made estimate
// (values, std, column norms chosen so that exactly one rule decides), their order, the
// model-level "not excited" line, and column_norms() against the rows folded.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "dynid/error.hpp"
#include "dynid/ls/accumulator.hpp"
#include "dynid/model/parameter_status.hpp"

namespace dynid::test {
namespace {

using ls::ParameterStatus;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

model::ParameterInfo info(const std::string& name, std::optional<double> typical, std::string by,
                          std::optional<double> lower = std::nullopt) {
  model::ParameterInfo p{name, "u", "", std::nullopt};
  p.typical = typical;
  p.excited_by = std::move(by);
  p.lower = lower;
  return p;
}

struct Case {
  std::vector<model::ParameterInfo> parameters;
  ls::Estimate estimate;
  Eigen::VectorXd norms;

  // One parameter: value, std, column norm. Residual norm 10 (so a term below 10 is noise).
  void add(model::ParameterInfo p, double value, double sigma, double norm,
           ParameterStatus structural = ParameterStatus::kIdentified) {
    parameters.push_back(std::move(p));
    const auto n = estimate.value.size();
    estimate.value.conservativeResize(n + 1);
    estimate.standard_deviation.conservativeResize(n + 1);
    estimate.relative_std_percent.conservativeResize(n + 1);
    norms.conservativeResize(n + 1);
    estimate.value(n) = value;
    estimate.standard_deviation(n) = sigma;
    estimate.relative_std_percent(n) = 100.0 * sigma / std::abs(value);
    norms(n) = norm;
    estimate.structure.status.push_back(structural);
    estimate.residual_norm = 10.0;
  }
  model::ModelVerdict classify() const { return model::classify_parameters(parameters, estimate, norms); }
};

TEST(ParameterStatus, WellDeterminedParametersAreIdentified) {
  Case c;
  c.add(info("mass", 1500.0, "d_vx"), 1480.0, 3.0, 1.0);      // term 1500 >> 10, 0.2 %
  c.add(info("offset", std::nullopt, "time"), 0.3, 0.002, 1e3);  // no scale, 0.67 %
  const auto v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kIdentified) << v.parameters[0].reason;
  EXPECT_EQ(v.parameters[1].status, ParameterStatus::kIdentified) << v.parameters[1].reason;
  EXPECT_EQ(v.parameters[0].reason, "");
  EXPECT_EQ(v.not_excited, "");
}

TEST(ParameterStatus, ATermBelowTheResidualAndAValueWithin2StdOfZeroIsNotExcited) {
  // A grade mass on a flat road: its column (norm 5e-3) times 1500 kg is 0.75 of the residual,
  // and -54 +- 88 kg cannot be told from zero.
  Case c;
  c.add(info("grade_mass", 1500.0, "road_grade (a hilly road)"), -54.0, 88.0, 5e-3);
  c.add(info("mass", 1500.0, "d_vx"), 1480.0, 3.0, 1.0);
  auto v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kNotExcited);
  EXPECT_NE(v.parameters[0].reason.find("0.75 of the residual and it is within 2 std of 0"), std::string::npos)
      << v.parameters[0].reason;
  EXPECT_NE(v.parameters[0].reason.find("needs road_grade (a hilly road)"), std::string::npos) << v.parameters[0].reason;
  EXPECT_EQ(v.parameters[1].status, ParameterStatus::kIdentified);
  EXPECT_EQ(v.not_excited, "");  // the model is excited: mass is identified
  // 2 std or more from zero is information, however small the term (the residual may be model
  // error): then DYCARO's rule decides.
  c.estimate.value(0) = -200.0;
  c.estimate.relative_std_percent(0) = 44.0;
  v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kPoorlyIdentified) << v.parameters[0].reason;
}

TEST(ParameterStatus, AStdAsLargeAsTheTypicalMagnitudeIsNotExcited) {
  // Rolling resistance at constant speed: a big column, but only together with drag.
  Case c;
  c.add(info("rolling_resistance", 200.0, "vx over a wide range"), 2996.0, 450.0, 1e3);
  c.add(info("mass", 1500.0, "d_vx"), 1480.0, 3.0, 1.0);
  auto v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kNotExcited);
  EXPECT_NE(v.parameters[0].reason.find("cannot tell it from 0"), std::string::npos) << v.parameters[0].reason;
  // Just under the scale it is information (then poorly identified: 199/2996 = 6.6 % > 10 x 0.2 %).
  c.estimate.standard_deviation(0) = 199.0;
  c.estimate.relative_std_percent(0) = 100.0 * 199.0 / 2996.0;
  v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kPoorlyIdentified) << v.parameters[0].reason;
}

TEST(ParameterStatus, WithoutAScaleExcitationIsNotJudged) {
  Case c;
  c.add(info("offset", std::nullopt, "time"), 0.5, 0.01, 1e-3);  // tiny column, no scale: 2 %
  c.add(info("other", std::nullopt, "x"), 2.0, 0.002, 1e3);      // 0.1 %
  const auto v = c.classify();
  // Not "not excited" (nothing to judge it against); DYCARO's k rule still applies.
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kPoorlyIdentified) << v.parameters[0].reason;
}

TEST(ParameterStatus, TheBoundIntervalIsTheScaleWhenNothingElseIs) {
  model::ParameterInfo friction{"mu", "-", "", std::nullopt};
  friction.lower = 0.0;
  friction.upper = 2.0;
  EXPECT_EQ(model::excitation_scale(friction), 2.0);
  friction.typical = 0.3;
  EXPECT_EQ(model::excitation_scale(friction), 0.3);
  friction.a_priori = -0.5;
  EXPECT_EQ(model::excitation_scale(friction), 0.5);
  friction.a_priori = 0.0;  // an a priori zero is no magnitude
  EXPECT_EQ(model::excitation_scale(friction), 0.3);
  EXPECT_FALSE(model::excitation_scale(info("offset", std::nullopt, "")).has_value());
}

TEST(ParameterStatus, OutsideTheBoundsByMoreThanTwoStdIsImplausible) {
  Case c;
  c.add(info("SCx", 0.7, "vx", 0.0), -6.7, 0.3, 100.0);     // 22 std below 0
  c.add(info("damping", 2000.0, "d_z", 0.0), -40.0, 30.0, 1.0);  // 1.3 std below 0: not implausible
  c.add(info("mass", 1500.0, "d_vx"), 1480.0, 3.0, 1.0);
  const auto v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kImplausible);
  EXPECT_NE(v.parameters[0].reason.find("outside its bounds > 0 by 22.33 std"), std::string::npos)
      << v.parameters[0].reason;
  EXPECT_NE(v.parameters[1].status, ParameterStatus::kImplausible) << v.parameters[1].reason;
  EXPECT_EQ(v.parameters[1].status, ParameterStatus::kPoorlyIdentified);  // 75 %
}

TEST(ParameterStatus, NotExcitedComesBeforeImplausible) {
  // A value out of bounds that the run knows nothing about says nothing about the car.
  Case c;
  c.add(info("SCx", 0.7, "vx over a wide range", 0.0), -6.7, 5.0, 100.0);
  const auto v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kNotExcited);
}

TEST(ParameterStatus, DycarosRuleAbsoluteAndKTimesTheSmallest) {
  Case c;
  c.add(info("a", std::nullopt, ""), 100.0, 0.02, 1.0);  // 0.02 %: the smallest
  c.add(info("b", std::nullopt, ""), 100.0, 0.5, 1.0);   // 0.5 %: > 10 x, but well estimated (< 1 %)
  c.add(info("c", std::nullopt, ""), 100.0, 2.0, 1.0);   // 2 %: > 10 x 0.02 %, > 1 %
  c.add(info("d", std::nullopt, ""), 100.0, 12.0, 1.0);  // 12 % > 10 %
  const auto v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kIdentified);
  EXPECT_EQ(v.parameters[1].status, ParameterStatus::kIdentified) << v.parameters[1].reason;
  EXPECT_EQ(v.parameters[2].status, ParameterStatus::kPoorlyIdentified);
  EXPECT_NE(v.parameters[2].reason.find("10 x the smallest (0.02 %, a)"), std::string::npos) << v.parameters[2].reason;
  EXPECT_EQ(v.parameters[3].status, ParameterStatus::kPoorlyIdentified);
  EXPECT_EQ(v.parameters[3].reason, "relative std 12 % > 10 %");
}

TEST(ParameterStatus, StructuralStatusesAreKept) {
  Case c;
  c.add(info("a", 1.0, "x"), 3.0, 0.01, 100.0, ParameterStatus::kRegrouped);
  c.add(info("b", 1.0, "y"), kNaN, kNaN, 100.0, ParameterStatus::kDependent);
  c.add(info("c", 1.0, "z (move it)"), kNaN, kNaN, 0.0, ParameterStatus::kEliminated);
  const auto v = c.classify();
  EXPECT_EQ(v.parameters[0].status, ParameterStatus::kRegrouped);
  EXPECT_EQ(v.parameters[1].status, ParameterStatus::kDependent);
  EXPECT_EQ(v.parameters[2].status, ParameterStatus::kEliminated);
  EXPECT_EQ(v.parameters[2].reason, "not excited: needs z (move it)");
  EXPECT_EQ(v.not_excited, "");  // a is regrouped: the model says something
}

TEST(ParameterStatus, AModelTheRunDoesNotExciteSaysWhatWould) {
  Case c;
  c.add(info("mass", 1500.0, "d_vx (accelerate, brake)"), 160.0, 2000.0, 1e3);
  c.add(info("SCx", 0.7, "vx over a wide range (coast down)", 0.0), -6.7, 5.0, 1e3);
  c.add(info("rolling_resistance", 200.0, "vx over a wide range (coast down)", 0.0), 2996.0, 450.0, 1e3);
  c.add(info("grade_mass", std::nullopt, "road_grade (hills)"), kNaN, kNaN, 0.0, ParameterStatus::kEliminated);
  const auto v = c.classify();
  for (std::size_t j = 0; j < 3; ++j) EXPECT_EQ(v.parameters[j].status, ParameterStatus::kNotExcited) << j;
  EXPECT_EQ(v.not_excited,
            "needs d_vx (accelerate, brake), vx over a wide range (coast down) and road_grade (hills)");
}

TEST(ParameterStatus, SizesMustAgree) {
  Case c;
  c.add(info("a", 1.0, "x"), 3.0, 0.01, 100.0);
  EXPECT_THROW(model::classify_parameters({}, c.estimate, c.norms), InputError);
  EXPECT_THROW(model::classify_parameters(c.parameters, c.estimate, Eigen::VectorXd(2)), InputError);
}

TEST(ParameterStatus, ColumnNormsAreThoseOfTheRowsFolded) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise;
  Eigen::MatrixXd W(200, 3);
  Eigen::VectorXd y(200);
  for (Eigen::Index i = 0; i < W.rows(); ++i) {
    W(i, 0) = noise(rng);
    W(i, 1) = 1000.0 * noise(rng);
    W(i, 2) = 1e-3 * noise(rng);
    y(i) = noise(rng);
  }
  ls::Accumulator acc(3);
  acc.fold(W.topRows(120), y.head(120));
  acc.fold(W.bottomRows(80), y.tail(80));
  const Eigen::VectorXd expected = W.colwise().norm().transpose();
  const Eigen::VectorXd got = model::column_norms(acc);
  for (Eigen::Index j = 0; j < 3; ++j) EXPECT_NEAR(got(j), expected(j), 1e-12 * expected(j)) << j;
}

}  // namespace
}  // namespace dynid::test
