// The residual loop's judgement (residual/noise_floor.hpp, residual/diagnosis.hpp) on synthetic
// runs whose noise is known: the channel noise read above the cut-off, the floor it makes
// through a model's rows, the stated rate of false alarms, and the three verdicts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "dynid/model/registry.hpp"
#include "dynid/residual/diagnosis.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/sensor_offset.hpp"
#include "dynid/residual/signal_delay.hpp"
#include "dynid/residual/trace.hpp"
#include "dynid/residual/varying_parameter.hpp"
#include "dynid/error.hpp"

namespace dynid::residual {
namespace {

constexpr double kRate = 100.0;
constexpr double kG = 9.80665;

// Units of the catalogue (docs/CHANNELS.md): models check them.
std::string unit_of(const std::string& channel) {
  if (channel == "ax" || channel == "ay") return "m/s^2";
  if (channel == "wheel_torque") return "N m";
  return channel == "yaw_rate" ? "rad/s" : "m/s";
}

ingest::RecordedRun recorded(const std::vector<std::pair<std::string, Eigen::VectorXd>>& channels) {
  ingest::RecordedRun run;
  run.announcement.vehicle = "synthetic";
  run.announcement.run = "r";
  run.announcement.sample_rate_hz = kRate;
  const Eigen::Index n = channels.front().second.size();
  run.samples.resize(n, static_cast<Eigen::Index>(channels.size()));
  for (std::size_t j = 0; j < channels.size(); ++j) {
    run.announcement.channels.push_back({channels[j].first, unit_of(channels[j].first)});
    run.samples.col(static_cast<Eigen::Index>(j)) = channels[j].second;
  }
  run.valid.assign(static_cast<std::size_t>(n), 1);
  return run;
}

double smooth(double t) { return 15.0 + 4.0 * std::sin(0.21 * t) + 1.5 * std::sin(0.9 * t + 0.3); }

// Over 20 runs: the measured std is unbiased, and the relative variance the bootstrap reports
// for sigma^2 is the scatter the runs show (within a factor 2).
TEST(ChannelNoise, ReadsTheStdOfWhiteNoiseUnderASlowSignalAndItsUncertainty) {
  constexpr int kRuns = 20;
  double sum = 0.0, square = 0.0, reported = 0.0;
  for (int seed = 0; seed < kRuns; ++seed) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    std::normal_distribution<double> n01;
    Eigen::VectorXd x(6000);
    for (Eigen::Index k = 0; k < x.size(); ++k) x(k) = smooth(static_cast<double>(k) / kRate) + 0.05 * n01(rng);
    const auto noise = measure_channel_noise(recorded({{"vx", x}}));
    ASSERT_EQ(noise.size(), 1U);
    EXPECT_EQ(noise[0].source, "measured above the cut-off");
    const double s2 = noise[0].sigma * noise[0].sigma;
    sum += s2;
    square += s2 * s2;
    reported += noise[0].level_relative_variance;
  }
  const double mean = sum / kRuns;
  const double scatter = (square / kRuns - mean * mean) / (mean * mean);
  EXPECT_NEAR(std::sqrt(mean), 0.05, 0.0025);
  EXPECT_GT(reported / kRuns, scatter / 2.0);
  EXPECT_LT(reported / kRuns, scatter * 2.0);
}

// Without the slow signal and over a long run, the measurement is unbiased to 1 %: raw minus
// low-passed raw leaks the filter's transition into the band's lowest bin through the window,
// which read white noise 4 % low in variance (2 % in std) until each bin was divided by its gain.
TEST(ChannelNoise, ReadsWhiteNoiseWithoutTheFiltersTransitionInTheBand) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n01;
  Eigen::VectorXd x(2'000'000);
  for (Eigen::Index k = 0; k < x.size(); ++k) x(k) = 0.05 * n01(rng);
  const auto noise = measure_channel_noise(recorded({{"vx", x}}));
  EXPECT_NEAR(noise[0].sigma / 0.05, 1.0, 0.01);
  EXPECT_LT(noise[0].level_relative_variance,
            0.0004);  // that 1 % is above the measurement's own scatter
}

TEST(ChannelNoise, ADeclaredStdReplacesTheMeasurement) {
  Eigen::VectorXd x(3000);
  for (Eigen::Index k = 0; k < x.size(); ++k) x(k) = smooth(static_cast<double>(k) / kRate);
  const auto declared = measure_channel_noise(recorded({{"vx", x}}), {{"vx", 0.2}});
  EXPECT_EQ(declared[0].sigma, 0.2);
  EXPECT_EQ(declared[0].source, "declared");
}

// A message at 25 Hz, interpolated linearly onto the 100 Hz grid: its noise (std s per message)
// lies mostly below 12.5 Hz. The in-band level is the 25 Hz white level, s^2 / 12.5 per Hz, so
// its white equivalent at 100 Hz is s^2 / 12.5 * 50 = (2 s)^2; the power above the cut-off,
// spread flat, would read about half of that.
TEST(ChannelNoise, ReadsTheInBandNoiseOfAChannelInterpolatedFromASlowerMessage) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> n01;
  const Eigen::Index n = 12000;
  std::vector<double> message;
  for (Eigen::Index m = 0; m <= n / 4; ++m) message.push_back(smooth(static_cast<double>(4 * m) / kRate) + 0.05 * n01(rng));
  Eigen::VectorXd x(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto m = static_cast<std::size_t>(k / 4);
    const double f = static_cast<double>(k % 4) / 4.0;
    x(k) = (1.0 - f) * message[m] + f * message[m + 1];
  }
  const auto noise = measure_channel_noise(recorded({{"vx", x}}));
  EXPECT_NEAR(noise[0].sigma, 0.10, 0.015);
}

// The kinematic model ax = s d_vx + o on a run whose only flaw is sensor noise: the residual is
// at the floor; the same run on a hilly road (no grade channel) is not.
ingest::RecordedRun kinematic_run(std::uint64_t seed, double grade_amplitude, double vx_late_s = 0.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  const Eigen::Index n = 6000;
  Eigen::VectorXd vx(n), ax(n);
  double s = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / kRate;
    const double dv = 4.0 * 0.21 * std::cos(0.21 * t) + 1.5 * 0.9 * std::cos(0.9 * t + 0.3);
    s += smooth(t) / kRate;
    const double grade = grade_amplitude * std::sin(s / 90.0);
    vx(k) = smooth(t - vx_late_s) + 0.02 * n01(rng);
    ax(k) = 1.02 * dv + 0.15 + kG * std::sin(grade) + 0.05 * n01(rng);
  }
  return recorded({{"vx", vx}, {"ax", ax}});
}

// The noise floor's draws change one channel of the run: preprocessing that channel again (and
// the derivative made from it) is exactly preprocessing the whole run, on runs with a gap (two
// segments) and with an announced channel named like a derivative (kept as announced).
TEST(NoiseFloor, PreprocessingOneChannelAgainEqualsPreprocessingTheRun) {
  auto run = kinematic_run(21, 0.02);
  run.announcement.channels.push_back({"d_ax", "m/s^3"});
  Eigen::MatrixXd samples(run.samples.rows(), 3);
  samples << run.samples, Eigen::VectorXd::LinSpaced(run.samples.rows(), 0.0, 1.0);
  run.samples = samples;
  for (Eigen::Index k = 2500; k < 2600; ++k) run.valid[static_cast<std::size_t>(k)] = 0;
  const auto base = ingest::preprocess_offline(run);
  ASSERT_EQ(base.size(), 2u);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01;
  for (Eigen::Index column = 0; column < 3; ++column) {
    auto changed = run;
    for (Eigen::Index k = 0; k < changed.samples.rows(); ++k) changed.samples(k, column) += 0.1 * n01(rng);
    const auto expected = ingest::preprocess_offline(changed);
    const auto again = ingest::preprocess_channel_again(changed, base, column);
    ASSERT_EQ(again.size(), expected.size());
    for (std::size_t s = 0; s < again.size(); ++s) {
      EXPECT_EQ(again[s].first, expected[s].first);
      ASSERT_EQ(again[s].channels.names(), expected[s].channels.names());
      for (const std::string& name : expected[s].channels.names())
        EXPECT_TRUE(again[s].channels[name] == expected[s].channels[name]) << "column " << column << ", " << name;
    }
  }
}

// The floor draws noise only for the channels the rows read (noise_floor.hpp, 2.): the kinematic
// model reads ax, and vx through its derivative only, and both must still be drawn (a check that
// missed the derivative would leave vx out of the floor); a channel it never reads (a yaw rate)
// leaves the floor exactly as without it. That the unread channel costs no draw is not
// observable here; bench/loop measures it.
TEST(NoiseFloor, OnlyTheChannelsTheRowsReadGetDraws) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  auto run = kinematic_run(3, 0.0);
  Eigen::MatrixXd samples(run.samples.rows(), 3);
  samples << run.samples, 0.1 * Eigen::VectorXd::LinSpaced(run.samples.rows(), -1.0, 1.0);
  run.samples = samples;
  run.announcement.channels.push_back({"yaw_rate", "rad/s"});
  const auto segments = ingest::preprocess_offline(run);
  const std::vector<ChannelNoise> read = {{"vx", 0.02, "declared"}, {"ax", 0.05, "declared"}};
  std::vector<ChannelNoise> first = read, last = read;
  first.insert(first.begin(), ChannelNoise{"yaw_rate", 0.01, "declared"});
  last.push_back(ChannelNoise{"yaw_rate", 0.01, "declared"});
  const std::vector<std::string> expected = {"vx", "ax"};
  EXPECT_EQ(noise_floor(*model, {}, run, segments, first, {}).contributing, expected);
  const NoiseFloor with = noise_floor(*model, {}, run, segments, last, {});
  const NoiseFloor without = noise_floor(*model, {}, run, segments, read, {});
  EXPECT_EQ(with.contributing, expected);
  ASSERT_EQ(with.groups.size(), 1U);
  ASSERT_EQ(without.groups.size(), 1U);
  EXPECT_GT(with.groups[0].floor_rms, 0.0);
  EXPECT_EQ(with.groups[0].floor_rms, without.groups[0].floor_rms);
  EXPECT_EQ(with.groups[0].ratio, without.groups[0].ratio);
}

// FloorCache (noise_floor.hpp): a draw dropped for the memory budget is drawn again the same, so
// a floor through a cache that can hold one draw at a time equals the floor through one that holds
// them all, bit for bit; and the cache holds no more than its budget and the draw just made.
TEST(NoiseFloor, ACacheOverItsBudgetDrawsAgainTheSameFloor) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  const auto run = kinematic_run(3, 0.0);
  const auto segments = ingest::preprocess_offline(run);
  const std::vector<ChannelNoise> noise = {{"vx", 0.02, "declared"}, {"ax", 0.05, "declared"}};
  FloorCache roomy(run, segments);
  FloorCache tight(run, segments, 1);
  const NoiseFloor all = noise_floor(*model, {}, run, segments, noise, {}, roomy);
  const NoiseFloor one = noise_floor(*model, {}, run, segments, noise, {}, tight);
  ASSERT_EQ(all.groups.size(), 1U);
  ASSERT_EQ(one.groups.size(), 1U);
  EXPECT_GT(all.groups[0].floor_rms, 0.0);
  EXPECT_EQ(one.groups[0].floor_rms, all.groups[0].floor_rms);
  EXPECT_EQ(one.groups[0].ratio, all.groups[0].ratio);
  EXPECT_EQ(one.groups[0].effective_rows, all.groups[0].effective_rows);
  const std::size_t one_draw = 2 * sizeof(double) * static_cast<std::size_t>(run.samples.rows());
  EXPECT_LE(tight.draw_bytes(), one_draw);
  EXPECT_GT(roomy.draw_bytes(), one_draw);  // every draw of both channels kept
}

TEST(NoiseFloor, AModelThatLacksNothingIsAdequateAtTheStatedRate) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  int adequate = 0;
  double ratios = 0.0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const Diagnosis d = diagnose(*model, {}, kinematic_run(seed, 0.0));
    ASSERT_EQ(d.floor.groups.size(), 1U);
    ratios += d.floor.groups[0].ratio;
    if (d.verdict == Verdict::kAdequate) ++adequate;
    else std::printf("seed %llu: %s\n", static_cast<unsigned long long>(seed), d.statement().c_str());
  }
  EXPECT_NEAR(ratios / 20.0, 1.0, 0.1);  // the floor is the residual's own level, unbiased
  EXPECT_GE(adequate, 18);  // 5 % false alarms: 1 expected in 20
}

TEST(Diagnosis, AnUnmeasuredGradeIsAboveTheFloorAndTracedToTheRoadProfile) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  const Diagnosis d = diagnose(*model, {}, kinematic_run(7, 0.04));
  std::printf("%s\n", d.statement().c_str());
  EXPECT_GT(d.floor.groups[0].ratio, 3.0);
  ASSERT_EQ(d.verdict, Verdict::kExplained) << d.statement();
  EXPECT_EQ(d.accepted->effect, "road_grade_profile");
}

// Structure no candidate can express: a residual that follows the run's time (a sensor drifting
// over the run) with the dictionary and the road profile switched off.
TEST(Diagnosis, StructureNoCandidateExplainsIsSaidWithItsSignature) {
  auto run = kinematic_run(9, 0.0);
  for (Eigen::Index k = 0; k < run.samples.rows(); ++k) run.samples(k, 1) += 0.4 * static_cast<double>(k) / 6000.0;
  const auto model = model::make_model("kinematic_longitudinal", {});
  DiagnosisOptions options;
  options.screen.dictionary = false;
  options.screen.road_profile = false;
  options.screen.varying_parameters = false;
  const Diagnosis d = diagnose(*model, {}, run, options);
  std::printf("%s\n", d.statement().c_str());
  ASSERT_EQ(d.verdict, Verdict::kStructureLeft) << d.statement();
  ASSERT_FALSE(d.signature.correlations.empty());
  const auto time = std::find_if(d.signature.correlations.begin(), d.signature.correlations.end(),
                                 [](const CorrelationFinding& f) { return f.channel == "time"; });
  ASSERT_NE(time, d.signature.correlations.end()) << "the drift's signature is its correlation with time";
  EXPECT_GT(time->correlation, 0.0);
}

// A sensor offset that drifts over the run is a parameter that is not constant: the drift
// candidate explains it, with the rate in the parameter's unit per second. (At this run's nearly
// constant speed a grade profile over distance explains it as well and is preferred: the screen
// is asked without the profile here.)
TEST(Diagnosis, ADriftingOffsetIsExplainedByItsDrift) {
  auto run = kinematic_run(9, 0.0);
  for (Eigen::Index k = 0; k < run.samples.rows(); ++k) run.samples(k, 1) += 0.4 * static_cast<double>(k) / 6000.0;
  const auto model = model::make_model("kinematic_longitudinal", {});
  DiagnosisOptions options;
  options.screen.road_profile = false;
  const Diagnosis d = diagnose(*model, {}, run, options);
  ASSERT_EQ(d.verdict, Verdict::kExplained) << d.statement();
  EXPECT_EQ(d.accepted->effect, "drift:sensor_offset");
  const EffectComparison c = compare_effect(*model, {}, "drift:sensor_offset", ingest::preprocess_offline(run),
                                            kRate, run.announcement.preprocessing.odmf);
  ASSERT_EQ(c.parameters.back().name, "sensor_offset_drift");
  EXPECT_EQ(c.parameters.back().unit, "m/s^2/s");
  EXPECT_NEAR(c.parameters.back().after, 0.4 / 60.0, 4.0 * c.parameters.back().std_after);
}

// The located delay's 95 % profile-likelihood interval holds the true delay: at least 7 of 10
// seeds (a calibrated interval fails that with probability 0.1 %). Measured: 9 of 10, the miss
// 20 ms off (two samples); two of the Gauss-Newton std it replaces (1-2 ms) held 200 ms only
// where the estimate was exact, 6 of 10.
TEST(Diagnosis, TheDelaysIntervalCoversTheTrueDelay) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  int covered = 0;
  for (std::uint64_t seed = 30; seed < 40; ++seed) {
    const Diagnosis d = diagnose(*model, {}, kinematic_run(seed, 0.0, 0.200));
    ASSERT_TRUE(d.accepted.has_value()) << d.statement();
    ASSERT_EQ(d.accepted->effect.rfind("delay:vx@", 0), 0U) << d.statement();
    const bool holds = d.accepted->located_from_s <= 0.200 && 0.200 <= d.accepted->located_to_s;
    std::printf("seed %llu: %s%s\n", static_cast<unsigned long long>(seed), d.accepted->finding.c_str(),
                holds ? "" : "  <- misses 200 ms");
    covered += holds ? 1 : 0;
  }
  EXPECT_GE(covered, 7);
}

// A sensor scale that changes with the distance travelled (a parameter drifting with a
// cumulative quantity), on a run that accelerates, so that distance (~ t^2) is not time: the
// drift with distance explains it, not the drift with time, its rate recovered per metre.
TEST(Diagnosis, AScaleThatDriftsWithDistanceIsExplainedByTheDistanceDrift) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> n01;
  const Eigen::Index n = 6000;
  Eigen::VectorXd vx(n), ax(n), distance(n);
  double s = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / kRate;
    const double v = 5.0 + 0.3 * t + 1.5 * std::sin(0.9 * t + 0.3);
    distance(k) = s;
    s += v / kRate;
    vx(k) = v + 0.02 * n01(rng);
  }
  const double mean_distance = distance.mean();
  constexpr double kPerMetre = 2e-4;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / kRate;
    const double dv = 0.3 + 1.35 * std::cos(0.9 * t + 0.3);
    ax(k) = (1.02 + kPerMetre * (distance(k) - mean_distance)) * dv + 0.15 + 0.05 * n01(rng);
  }
  const auto run = recorded({{"vx", vx}, {"ax", ax}});
  const auto model = model::make_model("kinematic_longitudinal", {});
  const Diagnosis d = diagnose(*model, {}, run);
  ASSERT_EQ(d.verdict, Verdict::kExplained) << d.statement();
  EXPECT_EQ(d.accepted->effect, "drift:sensor_scale~distance") << d.statement();
  const EffectComparison c = compare_effect(*model, {}, "drift:sensor_scale~distance", ingest::preprocess_offline(run),
                                            kRate, run.announcement.preprocessing.odmf);
  ASSERT_EQ(c.parameters.back().name, "sensor_scale_per_distance");
  EXPECT_EQ(c.parameters.back().unit, "- per m");
  EXPECT_NEAR(c.parameters.back().after, kPerMetre, 4.0 * c.parameters.back().std_after);
  EXPECT_THROW(parse_varying_effect("drift:sensor_scale~nothing", *model), InputError);
  EXPECT_THROW(parse_varying_effect("drift:nothing~distance", *model), InputError);
  EXPECT_EQ(cumulative_quantities({"vx", "ax"}), std::vector<std::string>{"distance"});
}

// A yaw-rate sensor with a bias (sensor_offset.hpp): in ay = s (d_vy + vx r) + o it acts as
// s vx b, not a constant, so the model's own offset cannot take it. Found as the sensor's
// offset, its value recovered, the model adequate once the rows read the sensor without it.
TEST(Diagnosis, ARateSensorBiasIsFoundAsTheSensorsOffset) {
  std::mt19937_64 rng(23);
  std::normal_distribution<double> n01;
  const Eigen::Index n = 6000;
  constexpr double kBias = 0.01;  // rad/s
  Eigen::VectorXd vx(n), vy(n), r(n), ay(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / kRate;
    const double speed = 15.0 + 4.0 * std::sin(0.21 * t);
    const double yaw = 0.1 * std::sin(0.5 * t) + 0.05 * std::sin(1.3 * t + 0.4);
    const double dvy = 0.3 * 0.5 * std::cos(0.5 * t + 0.5);
    vx(k) = speed + 0.02 * n01(rng);
    vy(k) = 0.3 * std::sin(0.5 * t + 0.5) + 0.002 * n01(rng);
    r(k) = yaw + kBias + 0.001 * n01(rng);
    ay(k) = dvy + speed * yaw + 0.05 * n01(rng);
  }
  const auto run = recorded({{"vx", vx}, {"vy", vy}, {"yaw_rate", r}, {"ay", ay}});
  const auto model = model::make_model("kinematic_lateral", {});
  const Diagnosis d = diagnose(*model, {}, run);
  ASSERT_EQ(d.verdict, Verdict::kExplained) << d.statement();
  const SensorOffset found = parse_offset_effect(d.accepted->effect);
  EXPECT_EQ(found.channel, "yaw_rate") << d.statement();
  EXPECT_NEAR(found.value, kBias, 4.0 * d.accepted->coefficient_std) << d.statement();
  EXPECT_EQ(d.accepted->finding.rfind("yaw_rate reads +", 0), 0U) << d.accepted->finding;
  EXPECT_NE(d.accepted->finding.find("rad/s too much"), std::string::npos) << d.accepted->finding;
  const Diagnosis after = diagnose(*model, {d.accepted->effect}, run);
  EXPECT_EQ(after.verdict, Verdict::kAdequate) << after.statement();
}

TEST(SensorOffset, NamesParseAndTheAngleAnAccelerometerOffsetMeans) {
  EXPECT_EQ(offset_effect_name("ay", 0.171), "offset:ay@+0.171");
  const SensorOffset o = parse_offset_effect("offset:ay@+0.171");
  EXPECT_EQ(o.channel, "ay");
  EXPECT_DOUBLE_EQ(o.value, 0.171);
  EXPECT_DOUBLE_EQ(parse_offset_effect("offset:yaw_rate@-0.002").value, -0.002);
  EXPECT_THROW(parse_offset_effect("offset:ay"), InputError);
  EXPECT_THROW(parse_offset_effect("offset:@1"), InputError);
  EXPECT_THROW(parse_offset_effect("offset:ay@nan"), InputError);
  EXPECT_THROW(parse_offset_effect("delay:ay@10ms"), InputError);
  // g sin(1 deg) = 0.17115 m/s^2 on ay: rolled by one degree.
  const std::string text = offset_finding("ay", "m/s^2", 9.80665 * std::sin(std::numbers::pi / 180.0), 0.001);
  EXPECT_NE(text.find("rolled +1.00"), std::string::npos) << text;
  EXPECT_NE(offset_finding("ax", "m/s^2", -0.17115, 0.001).find("pitched -1.00"), std::string::npos);
  EXPECT_EQ(offset_finding("yaw_rate", "rad/s", 0.01, 0.001).find("deg"), std::string::npos);
  EXPECT_TRUE(is_mounted_sensor("yaw_rate", "rad/s"));
  EXPECT_TRUE(is_mounted_sensor("ax", "m/s^2"));
  EXPECT_FALSE(is_mounted_sensor("engine_speed", "rad/s"));
  EXPECT_FALSE(is_mounted_sensor("d_vx", "m/s^2"));
}

// A sensor scale that grows with the speed (a parameter that depends on a channel): explained
// by depends:sensor_scale~vx, its slope recovered in the parameter's unit per unit of vx.
// Step times: every block boundary but the first and the last on a short run; on an hour's run
// every k-th, at most kMaxStepTimes per parameter, still on boundaries and evenly spread.
TEST(VaryingParameter, StepTimesAreBlockBoundariesAtMostABoundedNumberPerParameter) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  const auto step_times = [&](double t_last) {
    std::vector<double> out;
    for (const std::string& name : varying_candidates(*model, 0.0, t_last, 5.0, {}, {}))
      if (name.rfind("step:sensor_scale@", 0) == 0)
        out.push_back(parse_varying_effect(name, *model).step_time_s);
    return out;
  };
  EXPECT_EQ(step_times(40.0), (std::vector<double>{10, 15, 20, 25, 30, 35}));
  const std::vector<double> hour = step_times(3600.0);
  ASSERT_GE(hour.size(), static_cast<std::size_t>(kMaxStepTimes) - 1);
  ASSERT_LE(hour.size(), static_cast<std::size_t>(kMaxStepTimes));
  EXPECT_EQ(hour.front(), 10.0);
  for (std::size_t i = 1; i < hour.size(); ++i) {
    EXPECT_EQ(std::fmod(hour[i], 5.0), 0.0);
    EXPECT_EQ(hour[i] - hour[i - 1], hour[1] - hour[0]);
  }
  EXPECT_GE(hour.back(), 3600.0 - 5.0 - (hour[1] - hour[0]));
}

TEST(Diagnosis, AParameterThatDependsOnAChannelIsExplainedByTheDependence) {
  auto run = kinematic_run(17, 0.0);
  const auto clean = kinematic_run(17, 0.0);
  double mean = 0.0;
  for (Eigen::Index k = 0; k < run.samples.rows(); ++k) mean += smooth(static_cast<double>(k) / kRate);
  mean /= static_cast<double>(run.samples.rows());
  for (Eigen::Index k = 0; k < run.samples.rows(); ++k) {
    const double t = static_cast<double>(k) / kRate;
    const double dv = 4.0 * 0.21 * std::cos(0.21 * t) + 1.5 * 0.9 * std::cos(0.9 * t + 0.3);
    run.samples(k, 1) += 0.05 * (smooth(t) - mean) * dv;  // the scale changes by 0.05 per m/s
  }
  const auto model = model::make_model("kinematic_longitudinal", {});
  DiagnosisOptions options;
  options.screen.dependences = true;
  const Diagnosis d = diagnose(*model, {}, run, options);
  ASSERT_EQ(d.verdict, Verdict::kExplained) << d.statement();
  EXPECT_EQ(d.accepted->effect, "depends:sensor_scale~vx") << d.statement();
  const EffectComparison c = compare_effect(*model, {}, "depends:sensor_scale~vx", ingest::preprocess_offline(run),
                                            kRate, run.announcement.preprocessing.odmf);
  EXPECT_EQ(c.parameters.back().name, "sensor_scale_per_vx");
  EXPECT_NEAR(c.parameters.back().after, 0.05, 4.0 * c.parameters.back().std_after);
  EXPECT_EQ(diagnose(*model, {}, clean, options).verdict, Verdict::kAdequate);
  EXPECT_THROW(parse_varying_effect("depends:sensor_scale~", *model), InputError);
  EXPECT_THROW(parse_varying_effect("depends:nothing~vx", *model), InputError);
}

// A step of the sensor's scale at 30 s (a load change at a stop, a sensor re-mounted): found at
// its block boundary, located on the rows (the change point's 95 % set holds 30 s), its size
// recovered.
TEST(Diagnosis, AStepOfAParameterIsLocatedAndSized) {
  auto run = kinematic_run(11, 0.0);
  auto clean = kinematic_run(11, 0.0);
  for (Eigen::Index k = 3000; k < run.samples.rows(); ++k) {
    const double t = static_cast<double>(k) / kRate;
    const double dv = 4.0 * 0.21 * std::cos(0.21 * t) + 1.5 * 0.9 * std::cos(0.9 * t + 0.3);
    run.samples(k, 1) += 0.25 * dv;  // the scale goes from 1.02 to 1.27
  }
  const auto model = model::make_model("kinematic_longitudinal", {});
  const Diagnosis d = diagnose(*model, {}, run);
  ASSERT_EQ(d.verdict, Verdict::kExplained) << d.statement();
  const VaryingParameter step = parse_varying_effect(d.accepted->effect, *model);
  ASSERT_EQ(step.kind, VaryingParameter::Kind::kStep) << d.statement();
  EXPECT_EQ(step.parameter, "sensor_scale");
  EXPECT_LE(d.accepted->located_from_s, 30.0) << d.statement();
  EXPECT_GE(d.accepted->located_to_s, 30.0) << d.statement();
  EXPECT_LE(d.accepted->located_from_s, step.step_time_s);
  EXPECT_GE(d.accepted->located_to_s, step.step_time_s);
  EXPECT_LT(d.accepted->located_to_s - d.accepted->located_from_s, 5.0) << "finer than the screen's 5 s blocks";
  EXPECT_NE(d.accepted->finding.find("sensor_scale changes by"), std::string::npos) << d.accepted->finding;
  const EffectComparison c = compare_effect(*model, {}, d.accepted->effect, ingest::preprocess_offline(run),
                                            kRate, run.announcement.preprocessing.odmf);
  EXPECT_EQ(c.parameters.back().name, varying_parameter_info(step, *model).name);
  EXPECT_NEAR(c.parameters.back().after, 0.25, 4.0 * c.parameters.back().std_after);
  EXPECT_NEAR(c.parameters[0].after, 1.02, 4.0 * c.parameters[0].std_after);  // the value before the step
  EXPECT_EQ(diagnose(*model, {}, clean).verdict, Verdict::kAdequate);
}

// A load taken off at a stop, on a run whose speed is differentiated from noisy wheel speeds and
// whose accelerometer is sharp: driving with strong accelerations (0-50 s), a coast-down with the
// wheel torque at zero (50-100 s), a stop without valid data (100-112 s, the load of 200 kg taken
// off at 106 s), driving again. The mass's noise bias (errors in d_vx) differs between driving and
// coasting, so on the d_vx rows a mass step fits the phase boundary as well; the diagnosis judges
// the mass's time course with the accelerometer declared (diagnosis.hpp), where the step is
// located at the stop.
ingest::RecordedRun wheel_run(std::uint64_t seed, double mass_after) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  constexpr double kRadius = 0.3, kHalfRhoScx = 0.5 * 1.2 * 0.7, kRolling = 150.0;
  const Eigen::Index n = 18000;
  Eigen::VectorXd vx(n), ax(n), torque(n);
  double v = 12.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / kRate;
    const double mass = t < 106.0 ? 1500.0 : mass_after;
    const bool coasting = t >= 50.0 && t < 100.0;
    if (t >= 112.0 && t - 1.0 / kRate < 112.0) v = 12.0;
    const double resistance = kHalfRhoScx * v * v + kRolling;
    const double a =
        coasting ? -resistance / mass : 1.2 * std::sin(0.5 * t) + 0.6 * std::sin(1.3 * t + 0.4);
    const double force = coasting ? 0.0 : mass * a + resistance;
    vx(k) = v + 0.02 * n01(rng);
    ax(k) = a + 0.03 + 0.02 * n01(rng);
    torque(k) = kRadius * force + 3.0 * n01(rng);
    v += a / kRate;
  }
  ingest::RecordedRun run = recorded({{"vx", vx}, {"ax", ax}, {"wheel_torque", torque}});
  for (Eigen::Index k = 10000; k < 11200; ++k) run.valid[static_cast<std::size_t>(k)] = 0;
  return run;
}

TEST(Diagnosis, AParametersTimeCourseIsJudgedOnTheSharperSensorsRows) {
  const auto model =
      model::make_model("longitudinal_wheel", {{"wheel_radius", 0.3}, {"air_density", 1.2}});
  const Diagnosis d = diagnose(*model, {}, wheel_run(3, 1300.0));
  ASSERT_EQ(d.verdict, Verdict::kExplained) << d.statement();
  const VaryingParameter step = parse_varying_effect(d.accepted->effect, *model);
  ASSERT_EQ(step.kind, VaryingParameter::Kind::kStep) << d.statement();
  EXPECT_EQ(step.parameter, "mass");
  EXPECT_LE(d.accepted->located_from_s, 106.0) << d.accepted->finding;
  EXPECT_GE(d.accepted->located_to_s, 106.0) << d.accepted->finding;
  EXPECT_NEAR(d.accepted->coefficient, -200.0, 10.0) << d.accepted->finding;
  EXPECT_NE(d.accepted->finding.find("judged with road_grade_accelerometer declared"),
            std::string::npos)
      << d.accepted->finding;
  // Why: on the d_vx rows the step is located at the shift from driving to coasting, 55 s early.
  const auto on_dvx = std::find_if(
      d.screen.candidates.begin(), d.screen.candidates.end(), [](const CandidateScore& c) {
        return c.effect.rfind("step:mass@", 0) == 0 && std::isfinite(c.located_from_s) &&
               c.finding.find("judged with") == std::string::npos;
      });
  ASSERT_NE(on_dvx, d.screen.candidates.end());
  EXPECT_LT(on_dvx->located_to_s, 60.0) << on_dvx->finding;
  const auto refused =
      std::find_if(d.refused.begin(), d.refused.end(),
                   [&](const RefusedCandidate& r) { return r.effect == on_dvx->effect; });
  ASSERT_NE(refused, d.refused.end()) << d.statement();
  EXPECT_NE(refused->reason.find("time course is judged on the rows with road_grade_accelerometer"),
            std::string::npos)
      << refused->reason;
  const Diagnosis clean = diagnose(*model, {}, wheel_run(3, 1500.0));
  EXPECT_FALSE(clean.accepted && is_varying_effect(clean.accepted->effect)) << clean.statement();
}

// The speed signal recorded 200 ms late: the delay is found on the raw grid, named in ms with its
// interval, and once added the model is adequate. (At 80 ms this slow run's residual is 1.31
// times the floor's mean square, at the edge of the floor test: adequate.) Located within one
// sample here (190 ms); TheDelaysIntervalCoversTheTrueDelay measures the interval's coverage.
TEST(Diagnosis, ASignalRecordedLateIsFoundInMilliseconds) {
  const auto run = kinematic_run(13, 0.0, 0.200);
  const auto model = model::make_model("kinematic_longitudinal", {});
  const Diagnosis d = diagnose(*model, {}, run);
  ASSERT_EQ(d.verdict, Verdict::kExplained) << d.statement();
  const SignalDelay found = parse_delay_effect(d.accepted->effect, kRate);
  EXPECT_EQ(found.channel, "vx");
  EXPECT_NEAR(static_cast<double>(found.samples), 20.0, 1.0) << d.accepted->effect;
  EXPECT_EQ(d.accepted->finding.rfind("vx is ", 0), 0U) << d.accepted->finding;
  EXPECT_NE(d.accepted->finding.find(" ms late"), std::string::npos) << d.accepted->finding;
  EXPECT_LT(d.accepted->located_from_s, d.accepted->located_to_s) << d.accepted->finding;
  const Trace t = trace(*model, {}, run);
  EXPECT_EQ(t.added(), std::vector<std::string>{d.accepted->effect}) << t.stopped;
  EXPECT_EQ(t.rounds.back().diagnosis.verdict, Verdict::kAdequate) << t.rounds.back().diagnosis.statement();
  EXPECT_EQ(diagnose(*model, {}, kinematic_run(13, 0.0)).verdict, Verdict::kAdequate);
}

// The loop: the grade is explained by the road profile, added, and the model is then adequate;
// the before/after table carries the references' errors.
TEST(Trace, AddsTheEffectThatExplainsTheResidualThenStopsAtTheFloor) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  TraceOptions options;
  options.reference = {{"sensor_scale", 1.02}};
  const Trace t = trace(*model, {}, kinematic_run(7, 0.04), options);
  ASSERT_EQ(t.rounds.size(), 2U) << t.stopped;
  EXPECT_EQ(t.added(), std::vector<std::string>{"road_grade_profile"});
  EXPECT_EQ(t.rounds[1].effects, std::vector<std::string>{"road_grade_profile"});
  EXPECT_EQ(t.rounds[1].diagnosis.verdict, Verdict::kAdequate) << t.rounds[1].diagnosis.statement();
  EXPECT_EQ(t.stopped.rfind("adequate after 1 added effect", 0), 0U) << t.stopped;
  ASSERT_TRUE(t.rounds[0].added);
  const EffectComparison& c = *t.rounds[0].added;
  EXPECT_GT(c.held_out_drop(), 0.3);
  const auto scale = std::find_if(c.parameters.begin(), c.parameters.end(),
                                  [](const ParameterChange& p) { return p.name == "sensor_scale"; });
  ASSERT_NE(scale, c.parameters.end());
  ASSERT_TRUE(scale->truth);
  EXPECT_LT(std::abs(scale->error_after_percent()), std::abs(scale->error_before_percent()));

  options.max_rounds = 0;
  const Trace limited = trace(*model, {}, kinematic_run(7, 0.04), options);
  ASSERT_EQ(limited.rounds.size(), 1U);
  EXPECT_TRUE(limited.added().empty());
  EXPECT_NE(limited.stopped.find("limit of 0 added effects; road_grade_profile would be next"), std::string::npos)
      << limited.stopped;
}

TEST(Trace, AModelThatLacksNothingAddsNothing) {
  const auto model = model::make_model("kinematic_longitudinal", {});
  const Trace t = trace(*model, {}, kinematic_run(2, 0.0));
  EXPECT_TRUE(t.added().empty());
  EXPECT_EQ(t.stopped, "adequate after 0 added effects");
}

}  // namespace
}  // namespace dynid::residual
