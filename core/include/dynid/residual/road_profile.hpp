#pragma once
// RoadProfile: an unmeasured property of the road (its grade, its bank) as a function of the
// distance travelled, for the residual loop's "road profile" candidate.
//
// Why: a road grade or bank acts on the car through gravity, which the accelerometer reads and
// the wheel speeds do not (kinematic models) or which loads the drive force (longitudinal
// models). When no channel measures it (no GNSS grade), the residual of such an equation is
// g sin(grade(s)) (or g sin(bank(s))): a slowly varying function of the position s on the road,
// not of time or of the manoeuvre. The candidate models it as a piecewise-linear function of s
// (hat functions on knots every `knot_spacing` metres), one coefficient per knot and equation
// group. A profile so found is defined up to a constant where the model has an offset column
// (a constant grade and an accelerometer offset are the same column); its shape is what an
// independent grade (GNSS pose) can confirm.
//
// Fits report the profile's contribution centred on its mean over the rows (model_fit.hpp).
//
// Distance: the trapezoidal integral of the preprocessed vx over the valid segments; across a
// gap the speed is taken linear between the segments' end and start (the car did not stop
// reading). Contract: InputError when the segments lack vx or are not in increasing order.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"

namespace dynid::residual {

class RoadProfile {
 public:
  /// Knots every max(knot_spacing_m, 2 x the distance travelled in `held_out_block_s` at the
  /// run's mean speed): a knot interval longer than two held-out blocks keeps training rows on
  /// both sides of every knot, so a held-out block is predicted by interpolation, not by
  /// extrapolating one knot from the edges of its support.
  RoadProfile(const std::vector<ingest::PreprocessedSegment>& segments, double sample_period,
              double knot_spacing_m, double held_out_block_s = 0.0);

  double knot_spacing() const { return spacing_; }
  Eigen::Index knots() const { return knots_; }
  /// Knot positions, m from the run's first valid sample.
  double knot_distance(Eigen::Index knot) const { return spacing_ * static_cast<double>(knot); }
  /// Distance at a sample of a segment, m.
  double distance(std::size_t segment, Eigen::Index sample) const;
  /// The knots' hat functions at a distance: `out` has knots() entries, at most two non-zero,
  /// summing to 1.
  void hats(double distance_m, double* out) const;

 private:
  double spacing_;
  Eigen::Index knots_ = 0;
  std::vector<Eigen::VectorXd> distance_;  // per segment, per sample
};

/// The name of the road-profile candidate for a model: "road_grade_profile" when the model
/// knows a road_grade effect, "road_bank_profile" when it knows road_bank, else "road_profile".
std::string road_profile_effect_name(const model::Model& model);

/// True for the names road_profile_effect_name() gives.
bool is_road_profile_effect(const std::string& name);

}  // namespace dynid::residual
