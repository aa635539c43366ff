#pragma once
// The benchmark's effect families (issue 15, "It must show" 1-2): each draws, per seed, an
// effect that the second car's profile does not declare, with a random magnitude (and time or
// channel where it has one), injected into the simulated truth or its sensors, never into the
// model; and says what answer of the loop counts as right:
//   right       the candidate that is the physics (or the named varying parameter at the right
//               time, or the right signal's delay);
//   proxy       a labelled first-order proxy, named here with the reason it stands in;
//   structure   for the families no candidate is meant to express: "structure left";
// anything else the loop accepts is wrong; "adequate" is missed.
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "car/manoeuvres.hpp"
#include "car/perturbation.hpp"

namespace dynid::benchtrace {

enum class Expect { kCandidate, kStructureLeft, kCrossModel };

struct Draw {
  benchcar::Perturbation perturbation;
  std::string text;  ///< what was drawn, in words ("vx 120 ms late")
};

struct Family {
  std::string name;
  std::string kind;  ///< grade, wind, timing, step, drift, interaction, misalignment, ...
  benchcar::Manoeuvre manoeuvre;
  std::vector<std::string> models;  ///< traced; two for the cross-model family
  Expect expect = Expect::kCandidate;
  std::string right_text;  ///< the right answer, in words (the table's legend)
  std::function<Draw(std::mt19937_64&)> draw;
  /// Right: is `effect` the physics? (time-checked for steps, channel-checked for delays)
  std::function<bool(const std::string& effect, const Draw&)> right;
  /// A labelled first-order proxy (empty label: none counts).
  std::function<bool(const std::string& effect, const Draw&)> proxy;
  std::string proxy_label;
  /// "Reported as cannot be separated on this run" (separability.hpp) counts as right: the
  /// issue's answer for an effect nearly collinear with the declared columns (a head wind).
  bool inseparable_is_right = false;
};

const std::vector<Family>& families();

/// The models whose false-alarm rate is measured on clean runs, with their manoeuvre.
struct CleanCase {
  std::string model;
  benchcar::Manoeuvre manoeuvre;
};
const std::vector<CleanCase>& clean_cases();

}  // namespace dynid::benchtrace
