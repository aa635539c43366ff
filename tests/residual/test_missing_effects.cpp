// The residual loop on simulated runs that each hold one effect the model does not declare
// (issue 6; DESIGN.md "Residual loop"): the simulator's run goes through the product's data
// path (can.log -> car-side replay with the test car's profile -> chunks -> offline
// preprocessing), the screen ranks every candidate (physics, road profile, dictionary), and the
// true effect must rank first and be significant; adding it must lower the held-out residual and
// shrink the errors of the parameters whose truth the simulator knows. The before/after table
// is printed. On runs with no undeclared effect, at most one false alarm in 20 seeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "dynid/model/registry.hpp"
#include "dynid/residual/diagnosis.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/effect_screen.hpp"
#include "residual_test_support.hpp"
#include "sim_product_path.hpp"
#include "sim_test_support.hpp"

namespace dynid::residual {
namespace {

struct Case {
  std::string title;
  std::string scenario_file;
  std::string extra_toml;  // appended to the scenario
  std::string model;
  std::vector<std::string> declared;
  model::Constants constants;  // beyond the profile's
  bool tare = false;
  std::vector<std::string> true_effects;  // names that stand for the simulated effect
  std::map<std::string, std::string> truth_keys;  // model parameter -> truth.toml key
  std::map<std::string, double> truth_values = {};  // model parameter -> known value
  std::string manoeuvre_keys = {};                    // inserted into the scenario's [manoeuvre]
};

std::string scenario_text(const Case& c) {
  std::string text = sim::test::load_scenario_text(c.scenario_file);
  if (!c.manoeuvre_keys.empty()) {
    const std::string table = "[manoeuvre]\n";
    text.insert(text.find(table) + table.size(), c.manoeuvre_keys);
  }
  return text + c.extra_toml;
}

std::map<std::string, double> truth_of(const sim::Run& run, const Case& c) {
  std::map<std::string, double> out = c.truth_values;
  for (const auto& [parameter, key] : c.truth_keys) out[parameter] = sim::test::truth_value(run, key);
  return out;
}

// `may_be_at_floor`: an effect smaller than what the floor test can tell from the noise at its
// level (NoiseFloorOptions::error_rate); the verdict may then be "adequate", and the screen must
// still name the effect as its best significant candidate (the statement says so).
void expect_found_and_fixed(const Case& c, std::uint64_t seed, bool may_be_at_floor = false) {
  const sim::Run run = sim::test::run(scenario_text(c), seed);
  const ingest::ModelSpec spec = sim::test::model_spec(c.model, c.declared, c.constants);
  const test::ProcessedRun processed = test::process(run, spec, c.tare);
  const auto model = model::make_model(spec.model, spec.constants);
  const double rate = processed.announcement.sample_rate_hz;
  const int odmf = processed.announcement.preprocessing.odmf;

  const Diagnosis diagnosis = diagnose(*model, c.declared, processed.recorded);
  const ScreenResult& screen = diagnosis.screen;
  std::printf("\n#### %s (seed %llu): %s\n", c.title.c_str(), static_cast<unsigned long long>(seed),
              c.model.c_str());
  test::print_ranking(screen, 8);
  std::printf("%s\n", diagnosis.statement().c_str());
  // Found first: the candidate the loop adds, whether it explains the whole residual or a part
  // of it (diagnosis.hpp: "structure left" with the part named; measured here, the road bank
  // leaves the kinematic model's residual at 2.1 times its floor, the floor test's bound 1.35).
  const CandidateScore* named = screen.best();
  if (may_be_at_floor && diagnosis.verdict == Verdict::kAdequate) {
    ASSERT_NE(named, nullptr) << c.title << ": nothing significant at the floor";
    EXPECT_NE(diagnosis.statement().find(named->effect + " is significant all the same"), std::string::npos)
        << diagnosis.statement();
  } else {
    ASSERT_NE(diagnosis.verdict, Verdict::kAdequate) << c.title << ": " << diagnosis.statement();
    ASSERT_TRUE(diagnosis.accepted.has_value()) << c.title << ": " << diagnosis.statement();
    named = &*diagnosis.accepted;
  }
  const CandidateScore& best = *named;
  EXPECT_NE(std::find(c.true_effects.begin(), c.true_effects.end(), best.effect), c.true_effects.end())
      << c.title << ": explained by " << best.effect;

  const EffectComparison cmp = compare_effect(*model, c.declared, best.effect, processed.segments, rate, odmf,
                                              {}, truth_of(run, c));
  test::print_comparison(c.title, cmp);
  EXPECT_LT(cmp.after.weighted_rms_held_out, cmp.before.weighted_rms_held_out) << c.title;
  for (const GroupFit& g : cmp.after.groups) EXPECT_GT(g.rows, 0U);
  // Where the effect brings the model to its noise floor, every known parameter ends closer to
  // its truth, or within two of its standard deviations of it (an unbiased parameter may move
  // by noise). Where structure is left (diagnosis.partial: the loop says the model still lacks
  // something), what is left biases the parameters still, by more than their std can say (the
  // brake-drag run's pitch dynamics: its mass ends 3 std off); there the statement must say so.
  // At least one parameter must get strictly closer either way.
  const bool structure_left = diagnosis.partial.has_value();
  if (structure_left) {
    EXPECT_NE(diagnosis.statement().find("structure left"), std::string::npos) << diagnosis.statement();
  }
  int closer = 0;
  for (const ParameterChange& p : cmp.parameters) {
    if (!p.truth || std::isnan(p.before)) continue;  // the effect's own parameter has no before
    const double before = std::abs(p.before - *p.truth);
    const double after = std::abs(p.after - *p.truth);
    if (after < before) ++closer;
    if (structure_left) continue;
    EXPECT_TRUE(after < before || after <= 2.0 * p.std_after)
        << c.title << ": " << p.name << " error " << p.error_before_percent() << " % -> "
        << p.error_after_percent() << " % (std " << p.std_after << ")";
  }
  EXPECT_GE(closer, 1) << c.title << ": no parameter got closer to its truth";
}

const std::string kGradeProfile =
    "\n[road]\ngrade = [[0.0, 0.0], [60.0, 0.04], [160.0, -0.03], [260.0, 0.05], [380.0, -0.02], "
    "[520.0, 0.03], [5000.0, 0.0]]\n";
const std::string kBankProfile =
    "\n[road]\nbank = [[0.0, 0.0], [150.0, 0.06], [400.0, -0.05], [650.0, 0.07], [900.0, -0.04], "
    "[1200.0, 0.0], [5000.0, 0.0]]\n";

Case road_grade() {
  return {"road grade, longitudinal model", "acceleration.toml", kGradeProfile, "longitudinal_wheel", {}, {},
          true,
          {"road_grade", "road_grade_accelerometer", "road_grade_profile"},
          {{"mass", "vehicle.longitudinal_equivalent_mass"}, {"SCx", "vehicle.scx"},
           {"rolling_resistance", "vehicle.road_load_constant_force"}}};
}

Case anti_roll_bar() {
  return {"anti-roll bar, suspension model", "sine_steer.toml", "", "suspension_fl", {}, {}, false,
          {"anti_roll_bar"},
          {{"stiffness", "suspension.fl.stiffness"}, {"anti_roll_bar_stiffness", "suspension.fl.anti_roll_bar"}}};
}

// A clutch whose Stribeck speed (5 rad/s) lies inside the controlled-slip sweep; the engineer's
// profile gives the model that speed and only Coulomb + viscous friction.
Case stribeck() {
  return {"Stribeck friction, clutch model (Coulomb + viscous)", "slip_control.toml",
          "\n[driveline]\nclutch_stribeck_speed = 5.0\nclutch_mu_static = 0.20\n", "clutch_slip",
          {"viscous_friction", "engine_torque_offset"},
          {{"stribeck_speed", 5.0}, {"min_slip_speed", 2.0}, {"stick_margin", 0.4}, {"open_clamp_load", 150.0}},
          true,
          {"stribeck_friction"},
          {{"coulomb_friction", "driveline.clutch.mu_coulomb"}, {"viscous_friction", "driveline.clutch.mu_viscous"}}};
}

Case road_bank() {
  return {"road bank, lateral kinematic model", "sine_steer.toml", kBankProfile, "kinematic_lateral", {"roll_gravity"}, {},
          false, {"road_bank", "road_bank_profile"}, {}, {{"sensor_scale", 1.0}}};
}

// The driver rides the brake (up to 3 bar); the profile masks only braking above 10 bar.
Case brake_drag() {
  return {"brake drag, longitudinal model", "acceleration.toml", "", "longitudinal_wheel", {},
          {{"brake_pressure_threshold", 1.0e6}}, true, {"brake_drag"},
          {{"mass", "vehicle.longitudinal_equivalent_mass"}, {"SCx", "vehicle.scx"},
           {"rolling_resistance", "vehicle.road_load_constant_force"}},
          {}, "drag_pressure = 3.0e5\n"};
}

// Runs whose every effect the model declares: the loop must call the model adequate in at least
// 19 of 20 seeds (a false alarm is any other verdict: "explained" or "structure left").
int false_alarms(const Case& clean, std::uint64_t first_seed, int seeds) {
  int alarms = 0;
  for (std::uint64_t seed = first_seed; seed < first_seed + static_cast<std::uint64_t>(seeds); ++seed) {
    const sim::Run run = sim::test::run(scenario_text(clean), seed);
    const ingest::ModelSpec spec = sim::test::model_spec(clean.model, clean.declared, clean.constants);
    const test::ProcessedRun processed = test::process(run, spec, clean.tare);
    const auto model = model::make_model(spec.model, spec.constants);
    const Diagnosis d = diagnose(*model, clean.declared, processed.recorded);
    std::printf("%s, seed %llu: %s\n", clean.title.c_str(), static_cast<unsigned long long>(seed),
                d.statement().c_str());
    if (d.verdict != Verdict::kAdequate) ++alarms;
  }
  std::printf("%s: %d false alarms in %d runs\n", clean.title.c_str(), alarms, seeds);
  return alarms;
}

Case clean_clutch() {
  return {"clean clutch run", "slip_control.toml", "", "clutch_slip", {"viscous_friction", "engine_torque_offset"},
          {{"min_slip_speed", 2.0}, {"stick_margin", 0.4}, {"open_clamp_load", 150.0}}, true, {}, {}};
}

// A coast-down in neutral: no drive torque winds the shafts up, nothing the road-load model
// lacks (the acceleration runs are not clean for this model: the shafts' wind-up after each
// shift is in the rows, docs/RESIDUAL.md).
Case clean_coast_down() {
  return {"clean coast-down run", "coast_down.toml", "", "longitudinal_wheel", {}, {}, true, {}, {}};
}

Case clean_lateral() {
  return {"clean lateral run", "sine_steer.toml", "", "lateral_bicycle",
          {"tyre_saturation", "slip_offset", "roll_acceleration"}, {}, false, {}, {}};
}

// The clutch model with its viscous term and ECU offset on controlled-slip runs of a clutch whose
// Stribeck hump lies below the masked slips: every effect in the rows is declared.
TEST(MissingEffect, AtMostOneFalseAlarmInTwentyCleanRuns) { EXPECT_LE(false_alarms(clean_clutch(), 200, 20), 1); }

// The longitudinal model on coast-downs: the noisy wheel-speed derivative makes the accelerometer
// a "significant" candidate in every run, yet the residual is at the noise floor (issue 15).
TEST(MissingEffect, AtMostOneFalseAlarmInTwentyCleanCoastDowns) {
  EXPECT_LE(false_alarms(clean_coast_down(), 400, 20), 1);
}

// The same for the lateral model with the accuracy test's effects (tests/sim/test_accuracy.cpp),
// on five seeds (its residual keeps the tyres' load sensitivity, which no effect declares).
TEST(MissingEffect, AtMostOneFalseAlarmInFiveCleanLateralRuns) { EXPECT_LE(false_alarms(clean_lateral(), 300, 5), 1); }

TEST(MissingEffect, RoadGradeInTheLongitudinalModel) { expect_found_and_fixed(road_grade(), 61); }
// The bar's share of this sine steer's suspension residual is small: ratio of squares 1.37 against
// the floor test's 1.40 at its 2.5 % level (diagnosis.hpp: half the loop's false-alarm budget).
// The screen names it (HAC Wald p ~ 1e-39, held-out RMS -13 %), and adding it fixes the stiffness.
TEST(MissingEffect, AntiRollBarInTheSuspensionModel) { expect_found_and_fixed(anti_roll_bar(), 62, true); }
TEST(MissingEffect, StribeckInTheClutchModel) { expect_found_and_fixed(stribeck(), 63); }
TEST(MissingEffect, RoadBankInTheLateralKinematicModel) { expect_found_and_fixed(road_bank(), 64); }
TEST(MissingEffect, BrakeDragInTheLongitudinalModel) { expect_found_and_fixed(brake_drag(), 65); }

// A head wind on a coast-down: the aerodynamic force becomes 0.5 rho SCx (v + w)^2, i.e. SCx's
// own column plus a speed-proportional term (linear_drag's) plus a constant (rolling
// resistance's). On one run in one direction the speed-proportional term is nearly a
// combination of v^2 and 1: the loop either finds it (explained by linear_drag) or must say
// that it cannot be separated, with a bias at least as large as what the wind did to SCx.
TEST(MissingEffect, AHeadWindIsFoundOrReportedAsInseparableWithTheBiasItCauses) {
  const Case c{"head wind, acceleration", "acceleration.toml", "\n[vehicle]\nhead_wind = 8.0\n", "longitudinal_wheel",
               {}, {}, true, {"linear_drag"}, {{"SCx", "vehicle.scx"}}};
  const sim::Run run = sim::test::run(scenario_text(c), 66);
  const ingest::ModelSpec spec = sim::test::model_spec(c.model, c.declared, c.constants);
  const test::ProcessedRun processed = test::process(run, spec, c.tare);
  const auto model = model::make_model(spec.model, spec.constants);
  const Diagnosis d = diagnose(*model, c.declared, processed.recorded);
  std::printf("%s\n", d.statement().c_str());
  for (const Inseparable& i : d.inseparable) std::printf("%s\n", i.statement().c_str());
  if (d.accepted && d.accepted->effect == "linear_drag") return;
  const auto wind = std::find_if(d.inseparable.begin(), d.inseparable.end(),
                                 [](const Inseparable& i) { return i.effect == "linear_drag"; });
  ASSERT_NE(wind, d.inseparable.end()) << "the wind's term is neither found nor said to be inseparable";
  EXPECT_TRUE(wind->identifiable);
  EXPECT_NE(wind->separated_by.find("both directions"), std::string::npos) << wind->separated_by;
  // What the wind did to SCx is within what the report says the run cannot rule out.
  const std::vector<model::ParameterInfo> parameters = model->parameters_with(c.declared);
  const auto scx = static_cast<Eigen::Index>(
      std::find_if(parameters.begin(), parameters.end(), [](const model::ParameterInfo& p) { return p.name == "SCx"; }) -
      parameters.begin());
  const double error = d.screen.fit.estimate.value(scx) - sim::test::truth_value(run, "vehicle.scx");
  const double std_scx = d.screen.fit.estimate.standard_deviation(scx);
  std::printf("SCx error %.4g m^2 (std %.2g)\n", error, std_scx);
  EXPECT_GT(std::abs(error), 2.0 * std_scx) << "the wind did not bias SCx: the case tests nothing";
  ASSERT_EQ(wind->parameter.empty(), false);
  if (wind->parameter == "SCx") {
    EXPECT_GE(std::abs(wind->shift), std::abs(error) - 2.0 * std_scx);
  }
}

}  // namespace
}  // namespace dynid::residual
