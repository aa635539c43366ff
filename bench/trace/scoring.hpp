#pragma once
// Scoring one benchmark run: simulate the second car with a family's drawn effect (or none),
// send it through the product's data path, run the residual loop (residual::trace) on each of
// the family's models with the profile's declared effects, and classify the loop's first answer;
// check the loop's guarantees (no parameter ends outside its model's bounds; the held-out
// residual at the end not above where it started, on the declared fit's group weights).
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "car/manoeuvres.hpp"
#include "car/product_path.hpp"
#include "dynid/residual/trace.hpp"
#include "families.hpp"

namespace dynid::benchtrace {

enum class Outcome { kRight, kProxy, kStructureRight, kInseparable, kWrong, kMissed, kStructureMissed, kError };
const char* outcome_name(Outcome o);
/// Counts as the right answer (right physics, labelled proxy, or structure left where expected).
bool is_right(Outcome o);

struct ModelRun {
  std::string model;
  std::string first_verdict;  ///< the loop's first diagnosis
  std::string first_effect;   ///< its accepted candidate ("" when none)
  bool first_partial = false; ///< that candidate explains a part only (verdict "structure left")
  std::string first_finding;  ///< e.g. "vx is 120 +- 3 ms late"
  double first_located_from_s = std::nan("");  ///< a located step's 95 % set (effect_screen.hpp)
  double first_located_to_s = std::nan("");
  double first_ratio = 0.0;   ///< residual / floor (ratio of squares), worst group
  double first_upper = 0.0;   ///< the floor test's critical ratio there
  double second_ratio = 0.0;  ///< the same after the first added effect (0 when none was added)
  double second_upper = 0.0;
  std::vector<std::string> added;
  std::string stopped;
  std::string signature;      ///< the first diagnosis' strongest correlations, when structure is left
  bool bounds_ok = true;
  std::string bounds_violations;
  bool held_out_ok = true;
  double held_out_start = 0.0, held_out_end = 0.0;
  std::map<std::string, double> final_parameters;  ///< name -> value at the loop's end
  std::map<std::string, double> final_std;
  /// The physical effects the first diagnosis says this run cannot separate (separability.hpp).
  std::vector<std::string> first_inseparable;
  std::map<std::string, double> declared_parameters;  ///< the declared model's fit (round 0)
  std::map<std::string, double> declared_std;
  std::string report;  ///< the first diagnosis in full (RunSetup::verbose)
};

struct RunResult {
  std::string family;  ///< "clean" for clean runs
  std::uint64_t seed = 0;
  std::string drawn;
  Outcome outcome = Outcome::kError;
  std::vector<ModelRun> models;
  std::string error;
  /// The right answer (or its proxy) is among the effects the loop added, in any round.
  bool right_later = false;
  double seconds = 0.0;
  // The product's consistency check over the run's models as declared (residual/consistency.hpp):
  // any shared parameter beyond its level; and whether one common ratio explains it (a scale).
  bool cross_checked = false;
  bool cross_flagged = false;
  bool cross_one_ratio = false;
  std::string cross_text;
};

struct RunSetup {
  const car::VehicleProfile* profile = nullptr;
  std::filesystem::path work_dir;
  double noise_scale = 1.0;
  bool verbose = false;  ///< keep each model's first diagnosis report (ModelRun::report)
};

/// One family at one seed.
RunResult run_family(const RunSetup& setup, const Family& family, std::uint64_t seed);
/// A clean run of `manoeuvre` (no effect) with every listed model traced; outcome kRight when
/// every model is adequate, else kWrong (a false alarm) with per-model detail in `models`.
RunResult run_clean(const RunSetup& setup, benchcar::Manoeuvre manoeuvre, const std::vector<std::string>& models,
                    std::uint64_t seed);

}  // namespace dynid::benchtrace
