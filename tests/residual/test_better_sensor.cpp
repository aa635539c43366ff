// Hausman's test of a better sensor taken at the declared floor (residual/trace.hpp): a sensor
// that only lowers the noise sharpens the declared parameters without moving them; one that
// moves them beyond the difference's std is refused, naming the parameter that moved most.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "dynid/residual/trace.hpp"

namespace dynid::residual {
namespace {

ParameterChange change(const std::string& name, double before, double std_before, double after, double std_after) {
  ParameterChange p;
  p.name = name;
  p.unit = "u";
  p.before = before;
  p.std_before = std_before;
  p.after = after;
  p.std_after = std_after;
  return p;
}

EffectComparison comparison(std::vector<ParameterChange> parameters) {
  EffectComparison c;
  c.effect = "sensor";
  c.parameters = std::move(parameters);
  return c;
}

TEST(BetterSensor, AMoveWithinTheSharpenedNoiseIsAccepted) {
  // std 10 -> 6: the difference's std is 8; at 1 % over two parameters the bound is 2.81.
  const auto c = comparison({change("a", 100.0, 10.0, 120.0, 6.0), change("b", 5.0, 1.0, 5.5, 0.5)});
  EXPECT_EQ(better_sensor_refusal(c), "");
}

TEST(BetterSensor, AMoveBeyondItIsRefusedNamingTheParameterThatMovedMost) {
  // a moves 20 / 8 = 2.5 std of its difference (within); b from 5 to 8 with std 1 -> 0.5 moves
  // 3 / sqrt(0.75) = 3.46 std (beyond 2.81).
  const auto c = comparison({change("a", 100.0, 10.0, 120.0, 6.0), change("b", 5.0, 1.0, 8.0, 0.5)});
  const std::string why = better_sensor_refusal(c);
  EXPECT_NE(why.find("sensor refused"), std::string::npos) << why;
  EXPECT_NE(why.find("takes b from 5 to 8 u, 3.464 std"), std::string::npos) << why;
  EXPECT_NE(why.find("over 2 parameters"), std::string::npos) << why;
}

TEST(BetterSensor, WhereItDoesNotSharpenTheStdAreAddedAndTheEffectsOwnTermIsLeftOut) {
  // std 1 -> 2: the difference's std is taken as sqrt(1 + 4) = 2.24; a move of 5 is 2.24 std,
  // within the bound for one declared parameter (2.58; the effect's own term does not count).
  auto c = comparison({change("a", 0.0, 1.0, 5.0, 2.0)});
  ParameterChange own = change("sensor_term", std::numeric_limits<double>::quiet_NaN(), 0.0, 1e9, 1.0);
  c.parameters.push_back(own);
  EXPECT_EQ(better_sensor_refusal(c), "");
  c.parameters.front().after = 7.0;  // 3.13 > 2.58 (one declared parameter)
  EXPECT_NE(better_sensor_refusal(c), "");
}

// A part of the residual is no license to move the physics: a column more widens the declared
// parameters' std, and a move beyond the widening (std_after^2 - std_before^2) is refused.
TEST(PartialExplanation, AMoveBeyondTheWideningItAddsIsRefused) {
  // std 1 -> sqrt(2): the difference's std is 1; at 1 % over one parameter the bound is 2.58.
  auto c = comparison({change("yaw_inertia", 2130.0, 1.0, 2132.0, std::sqrt(2.0))});
  c.effect = "dict:d:vy";
  EXPECT_EQ(partial_refusal(c), "");
  c.parameters.front().after = 2140.0;  // 10 std
  const std::string why = partial_refusal(c);
  EXPECT_NE(why.find("dict:d:vy refused: it explains a part of the residual only"),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("yaw_inertia from 2130 to 2140 u, 10 std"), std::string::npos) << why;
  // A move of 3: 3 std of the widening, beyond 2.58; the better sensor's test, whose difference
  // variance is the sum (3) where the std widens, reads 1.73 std and would not refuse it.
  c.parameters.front().after = 2133.0;
  EXPECT_NE(partial_refusal(c), "");
  EXPECT_EQ(better_sensor_refusal(c), "");
}

}  // namespace
}  // namespace dynid::residual
