#include "smoke.hpp"

#include <map>
#include <cmath>
#include <cstdio>

#include "car/declared_fit.hpp"
#include "car/parameters.hpp"

namespace dynid::benchtrace {
namespace {

struct Check {
  int failures = 0;
  void expect(bool ok, const std::string& what) {
    std::printf("%s %s\n", ok ? "ok  " : "FAIL", what.c_str());
    if (!ok) ++failures;
  }
};

// The declared fit of `model` on a clean run of `manoeuvre`; each truth parameter within `tolerance`
// (relative).
void recover(Check& check, const RunSetup& setup, benchcar::Manoeuvre manoeuvre, const std::string& model,
             double noise_scale, std::uint64_t seed, const std::map<std::string, double>& tolerance) {
  const benchcar::CarParameters car;
  const benchcar::Perturbation none;
  const benchcar::Truth truth = benchcar::simulate(manoeuvre, car, none, seed);
  const std::string name = std::string("smoke-") + benchcar::manoeuvre_name(manoeuvre) + (noise_scale == 0.0 ? "-quiet" : "-noisy");
  const benchcar::ProductRun run = benchcar::through_product(*setup.profile, truth, none, {noise_scale, seed}, name, setup.work_dir);
  const residual::ModelFit fit = benchcar::declared_fit(*setup.profile, model, run.recorded);
  for (std::size_t i = 0; i < fit.parameters.size(); ++i) {
    const auto it = truth.parameters.find(fit.parameters[i].name);
    if (it == truth.parameters.end()) continue;
    const double v = fit.estimate.value(static_cast<Eigen::Index>(i));
    const double rel = std::abs(v / it->second - 1.0);
    const auto bound = tolerance.find(fit.parameters[i].name);
    char line[300];
    std::snprintf(line, sizeof line, "%s %s run: %s = %.8g against %.8g (relative error %.2e, bound %.0e)", model.c_str(),
                  noise_scale == 0.0 ? "noise-free" : "noisy", fit.parameters[i].name.c_str(), v, it->second, rel,
                  bound == tolerance.end() ? 0.0 : bound->second);
    if (bound != tolerance.end()) check.expect(rel <= bound->second, line);
    else
      std::printf("info %s (not checked: weakly excited on this run)\n", line);
  }
}

// The simulator against the clutch model's equation on its own 1 kHz truth, before any sensor:
// T_e = J_e dw_e/dt + R F mu(dw) on every launch sample (the clamp load rising, the clutch
// slipping) and T_e = J_e dw_e/dt on every clutch-open one (no load). dw_e/dt by the five-point
// central difference of the recorded engine speed (its error here below 1e-5 N m), except across
// the car's breakaway (the input shaft starts turning: the acceleration jumps there). Forward Euler
// on the idle return and a clutch torque held over the RK4 step each put the recorded torque half
// a step off its speeds: 0.06 N m, the clutch model's -0.1 % on J_e on a noise-free launch run.
void simulator_matches_the_clutch_equation(Check& check) {
  const benchcar::CarParameters car;
  const benchcar::Truth t = benchcar::simulate(benchcar::Manoeuvre::kLaunch, car, benchcar::Perturbation{}, 1);
  const std::vector<double>& we = t.channels.at("engine_speed");
  const std::vector<double>& wi = t.channels.at("gearbox_input_speed");
  const std::vector<double>& te = t.channels.at("engine_torque");
  const std::vector<double>& f = t.channels.at("clutch_clamp_load");
  const double h = 1.0 / t.rate_hz;
  double worst = 0.0, at = 0.0;
  std::size_t checked = 0;
  for (std::size_t k = 2; k + 2 < we.size(); ++k) {
    const double slip = we[k] - wi[k];
    const bool open = f[k - 2] == 0.0 && f[k] == 0.0 && f[k + 2] == 0.0;
    const bool engaging = f[k - 2] > 0.0 && f[k + 2] > f[k] && f[k] > f[k - 2] && slip > 1.0;
    if ((!open && !engaging) || (wi[k - 2] == 0.0) != (wi[k + 2] == 0.0)) continue;
    const double dwe = (we[k - 2] - 8.0 * we[k - 1] + 8.0 * we[k + 1] - we[k + 2]) / (12.0 * h);
    const double mu = car.clutch_mu_coulomb + car.clutch_mu_viscous * slip;
    const double r = te[k] - car.engine_inertia * dwe - car.clutch_radius * f[k] * mu;
    ++checked;
    if (std::abs(r) > worst) {
      worst = std::abs(r);
      at = t.time[k];
    }
  }
  char line[200];
  std::snprintf(line, sizeof line,
                "launch truth: T_e - J_e dw_e/dt - R F mu(dw) on %zu open or engaging samples: max %.2e N m at %.3f s "
                "(bound 1e-3)",
                checked, worst, at);
  check.expect(checked > 10000 && worst <= 1e-3, line);
}

}  // namespace

int run_smoke(const RunSetup& setup) {
  Check check;
  try {
    simulator_matches_the_clutch_equation(check);
    // Exactness of the second car through the product's path: no noise, IEEE-float logger signals.
    // The mass to 1e-5 (measured 1.9e-6), SCx and F_r to 1e-4 (measured 1.9e-5, 2.6e-5): what
    // the five-point derivative and the rows outside the filter's edge reach leave.
    recover(check, setup, benchcar::Manoeuvre::kCruise, "longitudinal_wheel", 0.0, 7,
            {{"mass", 1e-5}, {"SCx", 1e-4}, {"rolling_resistance", 1e-4}});
    // With the car's sensor noise: within a few percent (the well-excited parameters; the others are
    // printed).
    recover(check, setup, benchcar::Manoeuvre::kLongitudinal, "longitudinal_wheel", 1.0, 8, {{"mass", 0.05}});
    recover(check, setup, benchcar::Manoeuvre::kLateral, "lateral_bicycle", 1.0, 8,
            {{"yaw_inertia", 0.05}, {"front_cornering_stiffness", 0.05}, {"rear_cornering_stiffness", 0.05}});
    recover(check, setup, benchcar::Manoeuvre::kLaunch, "clutch_slip", 1.0, 8,
            {{"engine_inertia", 0.05}, {"coulomb_friction", 0.05}});
    // The harness, end to end, on two families (one seed): every run traced, no error.
    for (const char* name : {"speed_delay", "steer_delay"})
      for (const Family& f : families())
        if (f.name == name) {
          const RunResult r = run_family(setup, f, 1);
          check.expect(r.outcome != Outcome::kError && !r.models.empty() && !r.models.front().first_verdict.empty(),
                       f.name + " (" + r.drawn + "): " + outcome_name(r.outcome) + " " + r.error);
        }
    // Structure the declared signals' noise hides (residual/diagnosis.hpp): gusts that the
    // wheel-speed derivative's noise covers come out as structure left, through the
    // accelerometer's model (a part explained, or the accelerometer refused as a better sensor
    // that agrees with the published parameters, with what its model leaves); the same car on a
    // calm day stays adequate. A behaviour check on one seed each, not a score.
    for (const Family& f : families())
      if (f.name == "gusty_wind") {
        const RunResult r = run_family(setup, f, 1);
        const bool hidden = !r.models.empty() && r.models.front().first_verdict == "structure left";
        check.expect(hidden, f.name + " (" + r.drawn + "): first verdict '" +
                                 (r.models.empty() ? std::string("none") : r.models.front().first_verdict) +
                                 "', a part explained by '" + (r.models.empty() ? "" : r.models.front().first_effect) + "'");
      }
    const RunResult calm = run_clean(setup, benchcar::Manoeuvre::kLongitudinal, {"longitudinal_wheel"}, 1001);
    check.expect(calm.outcome == Outcome::kRight, "clean longitudinal run (seed 1001): " +
                                                      (calm.models.empty() ? std::string("none") : calm.models.front().first_verdict));
  } catch (const std::exception& e) {
    check.expect(false, std::string("exception: ") + e.what());
  }
  std::printf("%d failed checks\n", check.failures);
  return check.failures;
}

}  // namespace dynid::benchtrace
