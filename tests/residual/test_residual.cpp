// Unit tests of the residual loop's parts: the spectrum, column selection in the accumulator,
// exact recovery with a missing effect on noise-free data, the nothing-significant verdict, and
// bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>

#include "dynid/cancellation.hpp"
#include "dynid/error.hpp"
#include "dynid/ingest/recorded_run.hpp"
#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/residual/diagnosis.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/effect_screen.hpp"
#include "dynid/residual/spectrum.hpp"

namespace dynid::residual {
namespace {

constexpr double kRate = 50.0;
constexpr double kG = 9.80665;

TEST(Spectrum, ReadsTheAmplitudeOfASinusoidAtItsFrequency) {
  const Eigen::Index n = 1000;
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x(i) = 3.0 + 0.7 * std::sin(2.0 * std::numbers::pi * 5.0 * static_cast<double>(i) / 100.0);
  const Spectrum s = amplitude_spectrum(x, 0.01);
  Eigen::Index peak = 0;
  s.amplitude.maxCoeff(&peak);
  EXPECT_NEAR(s.frequency_hz(peak), 5.0, 0.1);
  EXPECT_NEAR(s.amplitude(peak), 0.7, 0.02);
  EXPECT_LT(s.amplitude(0), 1e-3);  // the mean is removed
  EXPECT_THROW(amplitude_spectrum(Eigen::VectorXd::Ones(3), 0.01), InputError);
  EXPECT_THROW(amplitude_spectrum(x, 0.0), InputError);
}

TEST(AccumulatorColumns, SelectingColumnsEqualsFoldingThoseColumnsOnly) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  const Eigen::MatrixXd W = Eigen::MatrixXd::NullaryExpr(300, 6, [&] { return n01(rng); });
  const Eigen::VectorXd y = Eigen::VectorXd::NullaryExpr(300, [&] { return n01(rng); });
  ls::Accumulator all(6);
  all.fold(W, y);
  const std::vector<Eigen::Index> cols{0, 2, 5};
  ls::Accumulator direct(3);
  direct.fold(W(Eigen::all, cols), y);
  const ls::Accumulator picked = all.select_columns(cols);
  EXPECT_EQ(picked.row_count(), 300U);
  const ls::Estimate a = ls::estimate(direct);
  const ls::Estimate b = ls::estimate(picked);
  EXPECT_LT((a.value - b.value).norm() / a.value.norm(), 1e-13);
  EXPECT_NEAR(a.residual_norm, b.residual_norm, 1e-12 * a.residual_norm);
  EXPECT_NEAR(a.sigma, b.sigma, 1e-12 * a.sigma);
  EXPECT_THROW(all.select_columns({2, 1}), InputError);
  EXPECT_THROW(all.select_columns({6}), InputError);
  EXPECT_THROW(all.select_columns({}), InputError);
}

// A car on a hilly road, noise free: ax = s d_vx + o + g sin(grade), grade measured by GNSS.
std::vector<ingest::PreprocessedSegment> hilly_run(double noise) {
  const Eigen::Index n = 3000;
  std::mt19937 rng(11);
  std::normal_distribution<double> n01;
  Eigen::VectorXd vx(n), dvx(n), ax(n), grade(n), steer(n);
  double s = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / kRate;
    vx(k) = 15.0 + 4.0 * std::sin(0.21 * t) + 1.5 * std::sin(0.9 * t);
    dvx(k) = 4.0 * 0.21 * std::cos(0.21 * t) + 1.5 * 0.9 * std::cos(0.9 * t);
    s += vx(k) / kRate;
    grade(k) = 0.04 * std::sin(s / 90.0) + 0.02 * std::sin(s / 160.0);
    steer(k) = 0.01 * std::sin(0.5 * t);
    ax(k) = 1.02 * dvx(k) + 0.15 + kG * std::sin(grade(k)) + noise * n01(rng);
  }
  ingest::PreprocessedSegment seg{0, model::ChannelSet(1.0 / kRate, n)};
  seg.channels.add("vx", "m/s", vx);
  seg.channels.add("d_vx", "m/s^2", dvx);
  seg.channels.add("ax", "m/s^2", ax);
  seg.channels.add("road_grade", "rad", grade);
  seg.channels.add("steer", "rad", steer);
  return {std::move(seg)};
}

TEST(EffectScreen, FindsTheMissingGradeAndRecoversTheParametersExactly) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  const auto run = hilly_run(0.0);
  const ScreenResult screen = screen_effects(*model, {}, run, kRate, 1);
  ASSERT_NE(screen.best(), nullptr) << screen.verdict();
  EXPECT_EQ(screen.best()->effect, "road_grade");
  EXPECT_EQ(screen.best()->kind, CandidateKind::kPhysics);
  EXPECT_GT(screen.best()->held_out_drop, 0.999);
  for (const CandidateScore& c : screen.candidates) {
    if (c.kind != CandidateKind::kDictionary) continue;  // an offset of ax is a sensor's, not a term of y
    EXPECT_EQ(c.effect.find(":ax"), std::string::npos) << "a dictionary term over the measured side: " << c.effect;
  }
  const EffectComparison cmp = compare_effect(*model, {}, "road_grade", run, kRate, 1, {},
                                              {{"sensor_scale", 1.02}, {"sensor_offset", 0.15}});
  for (const ParameterChange& p : cmp.parameters) {
    if (!p.truth) continue;
    EXPECT_NEAR(p.after, *p.truth, 1e-9 * std::abs(*p.truth)) << p.name;
  }
  EXPECT_NEAR(cmp.parameters.back().after, 1.0, 1e-9);  // the grade gain
  EXPECT_LT(cmp.after.groups[0].rms_in_sample, 1e-9);
  EXPECT_GT(cmp.before.groups[0].rms_in_sample, 0.1);
}

TEST(EffectScreen, TheRoadProfileFindsAnUnmeasuredGrade) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  const auto run = hilly_run(0.01);
  ScreenOptions options;
  options.only = {"road_grade_profile", "dict:x:vx", "dict:sq:vx", "dict:x:steer"};
  const ScreenResult screen = screen_effects(*model, {}, run, kRate, 5, options);
  ASSERT_NE(screen.best(), nullptr) << screen.verdict();
  EXPECT_EQ(screen.best()->effect, "road_grade_profile");
  EXPECT_GT(screen.best()->held_out_drop, 0.5);
}

// A declared road profile keeps its columns last: a candidate model effect is tested against the
// model with the profile, not against a shuffled column set.
TEST(EffectScreen, TestsCandidatesBesideADeclaredRoadProfile) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  const auto run = hilly_run(0.0);
  ScreenOptions options;
  options.only = {"road_grade", "dict:sq:vx"};
  const ScreenResult screen = screen_effects(*model, {"road_grade_profile"}, run, kRate, 1, options);
  ASSERT_EQ(screen.candidates.size(), 2U);
  for (const CandidateScore& c : screen.candidates) {
    EXPECT_TRUE(c.evaluated) << c.effect << ": " << c.note;
    EXPECT_EQ(c.columns, 1U) << c.effect;
    EXPECT_GE(c.in_sample_drop, 0.0) << c.effect;  // nested models: adding a column never hurts in sample
  }
  EXPECT_EQ(screen.candidates.front().effect, "road_grade");  // the exact grade beats its piecewise-linear profile
}

TEST(EffectScreen, SaysSoWhenNothingIsSignificant) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  auto run = hilly_run(0.05);
  ScreenOptions options;
  options.dictionary_all_channels = true;  // steer is no channel of this model's physics
  options.only = {"dict:x:steer", "dict:sq:steer", "dict:sgn:steer", "dict:x:vx", "dict:sq:vx"};
  const ScreenResult screen = screen_effects(*model, {"road_grade"}, run, kRate, 5, options);
  EXPECT_EQ(screen.best(), nullptr);
  EXPECT_EQ(screen.candidates.size(), 5U);
  EXPECT_NE(screen.verdict().find("nothing significant"), std::string::npos) << screen.verdict();
}

TEST(EffectScreen, NamesWhyACandidateCannotBeTested) {
  const auto model = model::make_model("longitudinal_wheel", {{"wheel_radius", 0.3}, {"air_density", 1.2}});
  const auto run = hilly_run(0.0);
  EXPECT_THROW(screen_effects(*model, {}, run, kRate, 1), InputError);  // no wheel_torque
  const auto kin = model::make_model("kinematic_longitudinal", {});
  ScreenOptions options;
  options.only = {"road_bank", "road_grade"};
  const ScreenResult screen = screen_effects(*kin, {}, run, kRate, 1, options);
  ASSERT_EQ(screen.candidates.size(), 1U);  // road_bank is not a candidate of this model
  CrossValidation bad;
  bad.folds = 1;
  EXPECT_THROW(bad.validate(), InputError);
  FitOptions wrong_weights;
  wrong_weights.group_weights = {1.0, 2.0};  // the model has one group
  EXPECT_THROW(fit_model(*kin, {}, run, kRate, 1, wrong_weights), InputError);
}

// dynid/cancellation.hpp: the loop's fits stop at their cancellation point once the installed
// Cancellation is cancelled, with its reason; without one, or after the scope, they run.
// Materiality (diagnosis.hpp): a candidate matters when it takes its model to the floor or removes
// at least the excess the floor test resolves, judged in the group where it removes most.
TEST(Materiality, WeighsTheMeanSquareRemovedAgainstTheFloorTestsResolution) {
  const auto group = [](const char* name, double residual_rms, double floor_rms,
                        double upper_ratio) {
    GroupFloor g;
    g.group = name;
    g.rows = 1000;
    g.residual_rms = residual_rms;
    g.floor_rms = floor_rms;
    g.ratio = residual_rms * residual_rms / (floor_rms * floor_rms);
    g.upper_ratio = upper_ratio;
    g.at_floor = g.ratio <= upper_ratio;
    return g;
  };
  NoiseFloor declared;
  declared.groups = {group("lateral", 10.5, 10.0, 1.36),
                     group("yaw", 12.5, 10.0, 1.25)};  // yaw 1.5625
  NoiseFloor small = declared;
  small.groups[1] = group("yaw", 12.3, 10.0, 1.25);  // removes 0.0494: a delay of 0 ms
  const Materiality s = materiality(declared, small);
  EXPECT_FALSE(s.material());
  EXPECT_EQ(s.group, "yaw");
  EXPECT_NEAR(s.removed, (12.5 * 12.5 - 12.3 * 12.3) / 100.0, 1e-12);
  EXPECT_NEAR(s.resolution, 0.25, 1e-12);
  NoiseFloor large = declared;
  large.groups[1] =
      group("yaw", 11.4, 10.0, 1.25);  // removes 0.2629 >= 0.25, still above its floor
  EXPECT_TRUE(materiality(declared, large).material());
  EXPECT_FALSE(materiality(declared, large).reaches);
  NoiseFloor reaching = declared;
  reaching.groups[1] = group("yaw", 11.1, 10.0, 1.25);  // removes 0.33, and reaches 1.2321 <= 1.25
  EXPECT_TRUE(materiality(declared, reaching).reaches);
  EXPECT_TRUE(materiality(declared, reaching).material());
}

// Structure a better sensor shows at the declared floor (diagnosis.hpp) is weighed like a
// candidate: its excess over the better sensor's own floor, in units of the declared floor's mean
// square, against the declared floor test's resolution; below it a note, not a verdict.
TEST(Materiality, HiddenStructureIsWeighedInTheDeclaredFloorsUnits) {
  NoiseFloor declared;
  GroupFloor d;
  d.group = "longitudinal";
  d.rows = 1000;
  d.residual_rms = 108.0;
  d.floor_rms = 100.0;
  d.upper_ratio = 1.2;
  declared.groups = {d};
  GroupFloor sensor = d;  // the accelerometer's model: far lower floor, far above it
  sensor.residual_rms = 28.0;
  sensor.floor_rms = 14.0;
  const HiddenStructure small = hidden_structure("road_grade_accelerometer", declared, sensor);
  EXPECT_NEAR(small.share, (28.0 * 28.0 - 14.0 * 14.0) / 1e4, 1e-12);  // 0.0588
  EXPECT_NEAR(small.resolution, 0.2, 1e-12);
  EXPECT_FALSE(small.material());
  EXPECT_NE(small.statement().find("immaterial"), std::string::npos) << small.statement();
  sensor.residual_rms = 46.0;  // 0.1920: still under what the declared floor resolves
  EXPECT_FALSE(hidden_structure("s", declared, sensor).material());
  sensor.residual_rms = 47.0;  // 0.2013
  EXPECT_TRUE(hidden_structure("s", declared, sensor).material());
  sensor.group = "yaw";  // no declared floor for it: nothing bounds it
  EXPECT_TRUE(hidden_structure("s", declared, sensor).material());
}

TEST(Cancellation, StopsTheLoopsFitsWithTheReasonOnlyWhileInstalled) {
  const auto kin = model::make_model("kinematic_longitudinal", {});
  const auto run = hilly_run(0.05);
  auto cancellation = std::make_shared<Cancellation>();
  EXPECT_FALSE(cancellation->cancelled());
  EXPECT_NO_THROW(cancellation_point());  // nothing installed
  {
    const CancellationScope scope(cancellation);
    EXPECT_NO_THROW(fit_model(*kin, {}, run, kRate, 5));  // installed, not cancelled
    cancellation->cancel("the client that asked has gone");
    cancellation->cancel("a second reason is not kept");
    EXPECT_EQ(cancellation->reason(), "the client that asked has gone");
    try {
      fit_model(*kin, {}, run, kRate, 5);
      ADD_FAILURE() << "a cancelled fit ran to its end";
    } catch (const Cancelled& e) {
      EXPECT_STREQ(e.what(), "cancelled: the client that asked has gone");
    }
    {
      const CancellationScope inner(nullptr);  // an inner scope without one: not cancelled
      EXPECT_NO_THROW(cancellation_point());
    }
    EXPECT_THROW(cancellation_point(), Cancelled);  // the outer one is back
  }
  EXPECT_NO_THROW(fit_model(*kin, {}, run, kRate, 5));  // the scope has ended
}

TEST(RecordedRun, RejectsMissingOrDisorderedChunksNamingThem) {
  ingest::RunAnnouncement a;
  a.vehicle = "car";
  a.run = "r1";
  a.sample_rate_hz = 100.0;
  a.channels = {{"vx", "m/s"}};
  auto chunk = [&](std::uint64_t seq, std::uint64_t first) {
    ingest::Chunk c{"car", "r1", seq, first, Eigen::MatrixXd::Constant(50, 1, 10.0),
                    std::vector<std::uint8_t>(50, 1), 0};
    c.seal();
    return c;
  };
  const ingest::RecordedRun ok = ingest::assemble_run(a, {chunk(0, 0), chunk(1, 50)});
  EXPECT_EQ(ok.samples.rows(), 100);
  try {
    (void)ingest::assemble_run(a, {chunk(0, 0), chunk(2, 50)});
    FAIL() << "a missing chunk was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("car/r1#2"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)ingest::assemble_run(a, {chunk(0, 0), chunk(1, 60)}), InputError);
  EXPECT_THROW((void)ingest::assemble_run(a, {}), InputError);
  const auto segments = ingest::preprocess_offline(ok);
  ASSERT_EQ(segments.size(), 1U);
  EXPECT_TRUE(segments[0].channels.has("d_vx"));
}

}  // namespace
}  // namespace dynid::residual
