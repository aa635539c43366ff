// Bad input: a clear error naming what and where, and the accumulator unchanged.
#include <gtest/gtest.h>

#include <limits>

#include "dynid/error.hpp"
#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"

namespace dynid::test {
namespace {

ls::Accumulator filled() {
  ls::Accumulator acc(4);
  Eigen::MatrixXd W = Eigen::MatrixXd::Random(20, 4);
  acc.fold(W, W * Eigen::Vector4d(1, 2, 3, 4) + Eigen::VectorXd::Random(20));
  return acc;
}

// Runs `action` on a copy of a filled accumulator: it must throw InputError whose message holds
// `expected`, and leave the state exactly as it was.
template <typename Action>
void expect_rejected(Action action, const std::string& expected) {
  ls::Accumulator acc = filled();
  const std::string before = acc.serialize();
  try {
    action(acc);
    FAIL() << "no error; expected one mentioning '" << expected << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
  EXPECT_EQ(acc.serialize(), before) << "state changed by a rejected call";
}

TEST(BadInput, NonFiniteRowsAreRejectedWithTheirPlace) {
  Eigen::MatrixXd W = Eigen::MatrixXd::Ones(6, 4);
  Eigen::VectorXd y = Eigen::VectorXd::Ones(6);
  W(3, 2) = std::numeric_limits<double>::quiet_NaN();
  expect_rejected([&](ls::Accumulator& a) { a.fold(W, y); }, "row 3, column 2 is NaN");
  W(3, 2) = 1.0;
  y(5) = -std::numeric_limits<double>::infinity();
  expect_rejected([&](ls::Accumulator& a) { a.fold(W, y); },
                  "measured side: row 5, column 0 is -Inf");
}

TEST(BadInput, WrongDimensionsAreRejected) {
  expect_rejected(
      [](ls::Accumulator& a) { a.fold(Eigen::MatrixXd::Ones(3, 5), Eigen::VectorXd::Ones(3)); },
      "5 columns, expected 4");
  expect_rejected(
      [](ls::Accumulator& a) { a.fold(Eigen::MatrixXd::Ones(3, 4), Eigen::VectorXd::Ones(2)); },
      "measured side has 2");
  expect_rejected([](ls::Accumulator& a) { a.fold_augmented(Eigen::MatrixXd::Ones(3, 4)); },
                  "expected 5");
  expect_rejected([](ls::Accumulator& a) { a.merge(ls::Accumulator(3)); }, "3 and 4 parameters");
  EXPECT_THROW(ls::Accumulator(0), InputError);
}

TEST(BadInput, BadScalingIsRejected) {
  for (double lambda : {0.0, -0.5, 1.5, std::numeric_limits<double>::quiet_NaN()})
    expect_rejected([&](ls::Accumulator& a) { a.forget(lambda); }, "lambda must be in (0, 1]");
  for (double w : {0.0, -1.0, std::numeric_limits<double>::infinity()})
    expect_rejected([&](ls::Accumulator& a) { a.scale_rows(w); }, "weight must be finite and > 0");
}

TEST(BadInput, EmptyAccumulatorHasNoEstimate) {
  EXPECT_THROW(ls::estimate(ls::Accumulator(3)), InputError);
}

void expect_bad_state(const std::string& bytes, const std::string& expected) {
  try {
    ls::Accumulator::deserialize(bytes);
    FAIL() << "accepted a bad state; expected '" << expected << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST(BadInput, TruncatedStateIsRejectedAtEveryLength) {
  const std::string good = filled().serialize();
  for (std::size_t len = 0; len < good.size(); ++len)
    expect_bad_state(good.substr(0, len), "truncated");
  expect_bad_state(good + "x", "trailing bytes");
}

TEST(BadInput, EveryFlippedBitIsDetected) {
  const std::string good = filled().serialize();
  for (std::size_t byte = 0; byte < good.size(); ++byte)
    for (int bit = 0; bit < 8; ++bit) {
      std::string bad = good;
      bad[byte] = static_cast<char>(bad[byte] ^ (1 << bit));
      EXPECT_THROW(ls::Accumulator::deserialize(bad), InputError)
          << "byte " << byte << " bit " << bit;
    }
}

TEST(BadInput, ForeignOrFutureStateIsNamed) {
  std::string bad = filled().serialize();
  bad[0] = 'X';
  expect_bad_state(bad, "bad magic");
  std::string future = filled().serialize();
  future[8] = 2;  // version field
  expect_bad_state(future, "unsupported format version 2");
}

}  // namespace
}  // namespace dynid::test
