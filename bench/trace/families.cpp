#include "families.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace dynid::benchtrace {
namespace {

using benchcar::Manoeuvre;
using benchcar::Perturbation;

double uniform(std::mt19937_64& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

std::string fmt(const char* format, double a, double b = 0.0) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, format, a, b);
  return buffer;
}

bool starts(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }
bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// "step:<p>@<t>s": the parameter and time, or time NaN when `effect` is no step of `parameter`.
double step_time(const std::string& effect, const std::string& parameter) {
  const std::string prefix = "step:" + parameter + "@";
  if (!starts(effect, prefix)) return std::nan("");
  return std::atof(effect.c_str() + prefix.size());
}

// A step of `parameter` within one cross-validation block (5 s) of the truth's time. The first
// answer's step must also hold the true time in its located 95 % set (scoring.cpp, kind "step").
bool step_near(const std::string& effect, const std::string& parameter, double t) {
  const double found = step_time(effect, parameter);
  return !std::isnan(found) && std::abs(found - t) <= 5.0;
}

auto never() {
  return [](const std::string&, const Draw&) { return false; };
}

// A road profile for the longitudinal run (~600 m): knots every 80..140 m, grades within +-amp.
std::vector<std::pair<double, double>> random_grade(std::mt19937_64& rng, double amplitude) {
  std::vector<std::pair<double, double>> g{{0.0, 0.0}};
  double x = 0.0;
  while (x < 900.0) {
    x += uniform(rng, 80.0, 140.0);
    g.emplace_back(x, uniform(rng, -amplitude, amplitude));
  }
  return g;
}

// One magnitude drawn uniformly in [lo, hi] into a field of the perturbation, described by
// `format` applied to value x scale.
std::function<Draw(std::mt19937_64&)> draw_value(double Perturbation::*field, double lo, double hi, const char* format,
                                                 double scale = 1.0) {
  return [=](std::mt19937_64& rng) {
    Draw d;
    d.perturbation.*field = uniform(rng, lo, hi);
    d.text = fmt(format, d.perturbation.*field * scale);
    return d;
  };
}

// A channel's sensor 40-200 ms late; right: the delay of that channel (any located value).
Family signal_delay(const std::string& name, Manoeuvre manoeuvre, const std::string& model, const std::string& channel,
                    const std::string& sensor) {
  return {name, "timing", manoeuvre, {model}, Expect::kCandidate,
          "delay:" + channel + "@<ms> (" + sensor + " 40-200 ms late)",
          [channel](std::mt19937_64& rng) {
            Draw d;
            const double s = uniform(rng, 0.04, 0.2);
            d.perturbation.delay[channel] = s;
            d.text = channel + fmt(" %.0f ms late", 1e3 * s);
            return d;
          },
          [channel](const std::string& e, const Draw&) { return starts(e, "delay:" + channel + "@"); }, never(), ""};
}

std::vector<Family> make_families() {
  std::vector<Family> f;
  // --- longitudinal_wheel, on the longitudinal run ---
  f.push_back({"road_grade", "grade", Manoeuvre::kLongitudinal, {"longitudinal_wheel"}, Expect::kCandidate,
               "road_grade_accelerometer or road_grade_profile (no GNSS grade on this car)",
               [](std::mt19937_64& rng) {
                 Draw d;
                 const double amp = uniform(rng, 0.02, 0.06);
                 d.perturbation.grade = random_grade(rng, amp);
                 d.text = fmt("grade knots within +-%.1f %%", 100 * amp);
                 return d;
               },
               [](const std::string& e, const Draw&) {
                 return e == "road_grade_accelerometer" || e == "road_grade_profile" || e == "road_grade";
               },
               [](const std::string& e, const Draw&) { return starts(e, "dict:") && (has(e, ":ax") || has(e, ":d_ax")); },
               "dict:*:ax (the accelerometer reads d_vx + g sin(grade): road_grade_accelerometer, unnamed)"});
  f.push_back({"head_wind", "wind", Manoeuvre::kLongitudinal, {"longitudinal_wheel"}, Expect::kCandidate,
               "linear_drag (a constant head wind w adds rho SCx w v, a linear drag, and 1/2 rho SCx w^2 to F_r)",
               draw_value(&Perturbation::head_wind, 5.0, 10.0, "head wind %.1f m/s"),
               [](const std::string& e, const Draw&) { return e == "linear_drag"; },
               [](const std::string& e, const Draw&) { return starts(e, "dict:x:vx"); },
               "dict:x:vx (the same column as linear_drag)", true});
  f.push_back({"brake_drag", "physics", Manoeuvre::kLongitudinal, {"longitudinal_wheel"}, Expect::kCandidate,
               "brake_drag (the driver rides the brake below the profile's 1 bar mask)",
               draw_value(&Perturbation::brake_drag_pressure, 0.2e5, 0.55e5, "%.2f bar mean brake drag", 1e-5),
               [](const std::string& e, const Draw&) { return e == "brake_drag"; }, never(), ""});
  f.push_back({"mass_step", "step", Manoeuvre::kLongitudinal, {"longitudinal_wheel"}, Expect::kCandidate,
               "step:mass whose located 95 % set holds the load change (at the stop: no row between the braking at 23 s and the relaunch at 31.6 s)",
               draw_value(&Perturbation::mass_step, 120.0, 400.0, "+%.0f kg at the stop"),
               // The car brakes from 23 s (braking rows are left out), stands from ~28.6 s, the load
               // changes at ~29.8 s and it rolls again past 1 m/s at ~31.6 s: no row lies between 23
               // and 31.6 s, so a step at any time there is the same model; its located set spans
               // the gap.
               [](const std::string& e, const Draw&) { return !std::isnan(step_time(e, "mass")); },
               [](const std::string& e, const Draw&) { return e == "drift:mass"; }, "drift:mass (a step seen as a trend)"});
  f.push_back(signal_delay("speed_delay", Manoeuvre::kLongitudinal, "longitudinal_wheel", "vx", "the optical speed sensor"));
  f.push_back({"gusty_wind", "inexpressible", Manoeuvre::kLongitudinal, {"longitudinal_wheel"}, Expect::kStructureLeft,
               "structure left (random gusts 0.3-1.5 Hz: an unmeasured force no candidate expresses)",
               [](std::mt19937_64& rng) {
                 Draw d;
                 d.perturbation.gust_amplitude = uniform(rng, 2.5, 4.0);
                 d.perturbation.seed = rng();
                 d.text = fmt("gusts 4 x %.1f m/s", d.perturbation.gust_amplitude);
                 return d;
               },
               never(), never(), ""});
  // --- longitudinal_engine ---
  f.push_back({"torque_speed_interaction", "interaction", Manoeuvre::kLongitudinal, {"longitudinal_engine"},
               Expect::kCandidate,
               "an interaction candidate over engine_speed (the ECU over-reports T_e by c w_e)",
               draw_value(&Perturbation::torque_per_engine_speed, 0.04, 0.1, "T_e over-reported by %.3f N m per rad/s"),
               [](const std::string& e, const Draw&) { return !starts(e, "dict:") && has(e, "engine_speed"); },
               [](const std::string& e, const Draw&) { return starts(e, "dict:") && has(e, "engine_speed"); },
               "dict:*:engine_speed (a column over engine speed, not scaled by the gear)"});
  f.push_back({"driveline_backlash", "inexpressible", Manoeuvre::kLongitudinal, {"longitudinal_engine"},
               Expect::kStructureLeft,
               "structure left (no torque reaches the wheels for 0.1-0.25 s after each torque reversal)",
               draw_value(&Perturbation::backlash_time, 0.1, 0.25, "lash %.0f ms per reversal", 1e3),
               never(), never(), ""});
  f.push_back({"wheel_torque_scale", "cross-model", Manoeuvre::kLongitudinal,
               {"longitudinal_wheel", "longitudinal_engine"}, Expect::kCrossModel,
               "a cross-model consistency finding (the wheel model alone fits a scaled car exactly)",
               [](std::mt19937_64& rng) {
                 Draw d;
                 const double s = uniform(rng, 0.06, 0.12) * (rng() % 2 ? 1.0 : -1.0);
                 d.perturbation.wheel_torque_scale = 1.0 + s;
                 d.text = fmt("wheel torque meter gain %+.1f %%", 100 * s);
                 return d;
               },
               [](const std::string& e, const Draw&) { return has(e, "consisten") || has(e, "cross"); }, never(), ""});
  // --- lateral_bicycle, on the lateral run ---
  f.push_back(signal_delay("steer_delay", Manoeuvre::kLateral, "lateral_bicycle", "steer", "the steering-angle sensor"));
  f.push_back({"rear_stiffness_step", "step", Manoeuvre::kLateral, {"lateral_bicycle"}, Expect::kCandidate,
               "step:rear_cornering_stiffness whose located 95 % set holds the drawn time",
               [](std::mt19937_64& rng) {
                 Draw d;
                 d.perturbation.rear_stiffness_step = -uniform(rng, 0.12, 0.3);
                 d.perturbation.step_time = uniform(rng, 9.0, 21.0);
                 d.text = fmt("C_r %+.0f %% at %.1f s", 100 * d.perturbation.rear_stiffness_step, d.perturbation.step_time);
                 return d;
               },
               [](const std::string& e, const Draw& d) {
                 return step_near(e, "rear_cornering_stiffness", d.perturbation.step_time);
               },
               [](const std::string& e, const Draw& d) {
                 return step_near(e, "front_cornering_stiffness", d.perturbation.step_time) ||
                        step_near(e, "yaw_inertia", d.perturbation.step_time);
               },
               "a step of another parameter at the right time (the axle's balance seen through another column)"});
  f.push_back({"front_stiffness_drift", "drift", Manoeuvre::kLateral, {"lateral_bicycle"}, Expect::kCandidate,
               "drift:front_cornering_stiffness (tyres warming up)",
               [](std::mt19937_64& rng) {
                 Draw d;
                 d.perturbation.front_stiffness_drift = uniform(rng, 0.15, 0.35) * (rng() % 2 ? 1.0 : -1.0);
                 d.text = fmt("C_f %+.0f %% over the run", 100 * d.perturbation.front_stiffness_drift);
                 return d;
               },
               [](const std::string& e, const Draw&) { return e == "drift:front_cornering_stiffness"; },
               [](const std::string& e, const Draw&) {
                 return starts(e, "step:front_cornering_stiffness@") || e == "drift:front_cornering_stiffness~distance";
               },
               "step:front_cornering_stiffness (a trend seen as a step), or a drift with distance (the same trend at a steady speed)"});
  f.push_back({"load_sensitivity", "interaction", Manoeuvre::kLateral, {"lateral_bicycle"}, Expect::kCandidate,
               "an interaction candidate (stiffness x ay^2); proxy tyre_saturation (|d| d ~ d |ay|)",
               [](std::mt19937_64& rng) {
                 Draw d;
                 const double drop = uniform(rng, 0.08, 0.2);  // at |ay| = 4 m/s^2
                 d.perturbation.load_sensitivity = drop / 16.0;
                 d.text = fmt("C -%.0f %% at 4 m/s^2", 100 * drop);
                 return d;
               },
               [](const std::string& e, const Draw&) { return has(e, "interaction") || has(e, "load"); },
               [](const std::string& e, const Draw&) { return e == "tyre_saturation"; },
               "tyre_saturation (|d| d: the force's fall with slip, which follows ay)"});
  f.push_back({"imu_roll_mount", "misalignment", Manoeuvre::kLateral, {"lateral_bicycle"}, Expect::kCandidate,
               "offset:ay (the accelerometer reads g sin(phi): a roll of its mount); proxy slip_offset (the ay offset as constant slip offsets)",
               [](std::mt19937_64& rng) {
                 Draw d;
                 const double deg = uniform(rng, 0.6, 2.0) * (rng() % 2 ? 1.0 : -1.0);
                 d.perturbation.imu_roll_mount = deg * 3.14159265358979 / 180.0;
                 d.text = fmt("accelerometer rolled %+.1f deg on its mount", deg);
                 return d;
               },
               [](const std::string& e, const Draw&) { return starts(e, "offset:ay@"); },
               [](const std::string& e, const Draw&) { return e == "slip_offset" || e == "steer_offset"; },
               "slip_offset / steer_offset (constant forces that absorb an ay offset)"});
  f.push_back({"tyre_relaxation", "inexpressible", Manoeuvre::kLateral, {"lateral_bicycle"}, Expect::kStructureLeft,
               "structure left (slip angles lag through sigma / vx); proxy a delay of steer",
               [](std::mt19937_64& rng) {
                 Draw d;
                 d.perturbation.relaxation_length = uniform(rng, 0.5, 1.2);
                 d.text = fmt("relaxation length %.2f m (%.0f ms at 20 m/s)", d.perturbation.relaxation_length,
                              d.perturbation.relaxation_length / 20.0 * 1e3);
                 return d;
               },
               never(), [](const std::string& e, const Draw&) { return starts(e, "delay:steer@"); },
               "delay:steer (a first-order lag looks like a delay below its corner)"});
  // --- clutch_slip, on the launch run ---
  f.push_back({"clutch_fade", "drift", Manoeuvre::kLaunch, {"clutch_slip"}, Expect::kCandidate,
               "drift:coulomb_friction~clutch_energy (mu_c falls with the energy the clutch dissipates); proxy a drift with time",
               draw_value(&Perturbation::clutch_fade, 0.2, 0.4, "mu_c -%.0f %% per 100 kJ", 100.0),
               [](const std::string& e, const Draw&) { return e == "drift:coulomb_friction~clutch_energy"; },
               [](const std::string& e, const Draw&) {
                 return e == "drift:coulomb_friction" || starts(e, "step:coulomb_friction@");
               },
               "drift:/step:coulomb_friction (energy accumulates over the launches: a trend in time)"});
  f.push_back({"stribeck", "physics", Manoeuvre::kLaunch, {"clutch_slip"}, Expect::kCandidate,
               "stribeck_friction (the profile's v_s = 6 rad/s; the true v_s drawn 4-8)",
               [](std::mt19937_64& rng) {
                 Draw d;
                 d.perturbation.stribeck_rise = uniform(rng, 0.04, 0.09);
                 d.perturbation.stribeck_speed = uniform(rng, 4.0, 8.0);
                 d.text = fmt("mu_s - mu_c = %.3f at v_s %.1f rad/s", d.perturbation.stribeck_rise,
                              d.perturbation.stribeck_speed);
                 return d;
               },
               [](const std::string& e, const Draw&) { return e == "stribeck_friction"; }, never(), ""});
  f.push_back({"ecu_torque_offset", "physics", Manoeuvre::kLaunch, {"clutch_slip"}, Expect::kCandidate,
               "engine_torque_offset",
               [](std::mt19937_64& rng) {
                 Draw d;
                 d.perturbation.ecu_torque_offset = uniform(rng, 6.0, 15.0) * (rng() % 2 ? 1.0 : -1.0);
                 d.text = fmt("ECU torque offset %+.1f N m", d.perturbation.ecu_torque_offset);
                 return d;
               },
               [](const std::string& e, const Draw&) { return e == "engine_torque_offset"; }, never(), ""});
  return f;
}

}  // namespace

const std::vector<Family>& families() {
  static const std::vector<Family> f = make_families();
  return f;
}

const std::vector<CleanCase>& clean_cases() {
  static const std::vector<CleanCase> c = {{"longitudinal_wheel", Manoeuvre::kLongitudinal},
                                           {"longitudinal_engine", Manoeuvre::kLongitudinal},
                                           {"lateral_bicycle", Manoeuvre::kLateral},
                                           {"clutch_slip", Manoeuvre::kLaunch}};
  return c;
}

}  // namespace dynid::benchtrace
