// Hausman's comparison of SIMEX with IV (residual/simex_against_iv.hpp): the rule's arithmetic on
// fits built by hand, every branch: agreement, disagreement beyond the Bonferroni bound, a
// parameter SIMEX is not more precise for, and the fits it must not compare.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "dynid/residual/simex_against_iv.hpp"

namespace dynid::residual {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

model::ParameterInfo named(const std::string& name) {
  model::ParameterInfo p;
  p.name = name;
  return p;
}

// Two parameters; IV's HAC std 5 and 10, SIMEX's 3 and 6 (more precise). IV - LS has std 2.4
// and 4.8, SIMEX's correction Monte Carlo 1.8 and 3.6 and noise-level 1.6 and 3.2: the
// differences' std are sqrt(2.4^2 + 1.8^2 + 1.6^2) = 3.4 and 6.8.
struct Fits {
  IvFit iv;
  SimexFit simex;
  Fits() {
    iv.model = simex.model = "lateral_bicycle";
    iv.parameters = simex.parameters = {named("a"), named("b")};
    iv.value = Eigen::Vector2d(100.0, 200.0);
    iv.hac_std = Eigen::Vector2d(5.0, 10.0);
    iv.difference_std = Eigen::Vector2d(2.4, 4.8);
    simex.value = Eigen::Vector2d(100.0, 200.0);
    simex.std = Eigen::Vector2d(3.0, 6.0);
    simex.monte_carlo_std = Eigen::Vector2d(1.8, 3.6);
    simex.level_std = Eigen::Vector2d(1.6, 3.2);
    simex.contributing = {"steer"};
  }
};

// Bonferroni over 2 parameters at 1 %: 0.5 % each, two-sided, z = 2.807.
constexpr double kBound = 2.807;

TEST(SimexAgainstIv, SimexStandsWhereTheDifferencesAreWithinTheirHausmanStd) {
  Fits f;
  f.simex.value = Eigen::Vector2d(100.0 + 0.99 * kBound * 3.4, 200.0 - 0.99 * kBound * 6.8);
  const SimexAgainstIv c = compare_simex_with_iv(f.iv, f.simex);
  EXPECT_TRUE(c.compared);
  EXPECT_TRUE(c.simex_stands);
  EXPECT_EQ(c.parameters, 2);
  EXPECT_DOUBLE_EQ(c.level, 0.005);
  EXPECT_NEAR(c.largest_z, 0.99 * kBound, 1e-12);
  EXPECT_NE(c.statement().find("SIMEX published"), std::string::npos) << c.statement();
}

TEST(SimexAgainstIv, IvStaysWhereOneDifferenceIsBeyondTheBound) {
  Fits f;
  f.simex.value(1) = 200.0 + 1.01 * kBound * 6.8;
  const SimexAgainstIv c = compare_simex_with_iv(f.iv, f.simex);
  EXPECT_TRUE(c.compared);
  EXPECT_FALSE(c.simex_stands);
  EXPECT_EQ(c.deciding, "b");
  EXPECT_NEAR(c.largest_z, 1.01 * kBound, 1e-12);
  EXPECT_NE(c.statement().find("IV kept"), std::string::npos) << c.statement();
}

TEST(SimexAgainstIv, IvStaysWhereSimexIsNotMorePreciseForAParameter) {
  Fits f;
  f.simex.std(0) = 5.0;  // equal to IV's: nothing gained
  const SimexAgainstIv c = compare_simex_with_iv(f.iv, f.simex);
  EXPECT_TRUE(c.compared);
  EXPECT_FALSE(c.simex_stands);
  EXPECT_EQ(c.deciding, "a");
  EXPECT_TRUE(std::isnan(c.largest_z));
  EXPECT_NE(c.statement().find("not more precise for a"), std::string::npos) << c.statement();
}

TEST(SimexAgainstIv, AParameterOneOfThemDoesNotEstimateIsLeftOutOfTheFamily) {
  Fits f;
  f.iv.value(1) = kNaN;
  f.simex.value(0) = 100.0 + 1.01 * 2.576 * 3.4;  // beyond the 1 % bound of one parameter
  const SimexAgainstIv c = compare_simex_with_iv(f.iv, f.simex);
  EXPECT_EQ(c.parameters, 1);
  EXPECT_DOUBLE_EQ(c.level, 0.01);
  EXPECT_FALSE(c.simex_stands);
}

TEST(SimexAgainstIv, FitsItMustNotCompareAreNotCompared) {
  {
    Fits f;
    f.iv.refused = true;
    EXPECT_FALSE(compare_simex_with_iv(f.iv, f.simex).compared);
  }
  {
    Fits f;
    f.simex.contributing.clear();  // no noise corrected: SIMEX is least squares
    EXPECT_FALSE(compare_simex_with_iv(f.iv, f.simex).compared);
  }
  {
    Fits f;
    f.simex.parameters[1] = named("c");  // another effect set's columns
    EXPECT_FALSE(compare_simex_with_iv(f.iv, f.simex).compared);
  }
  {
    Fits f;
    f.simex.model = "clutch_slip";
    const SimexAgainstIv c = compare_simex_with_iv(f.iv, f.simex);
    EXPECT_FALSE(c.compared);
    EXPECT_FALSE(c.simex_stands);
    EXPECT_NE(c.statement().find("not compared"), std::string::npos);
  }
}

}  // namespace
}  // namespace dynid::residual
