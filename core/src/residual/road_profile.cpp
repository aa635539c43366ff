#include "dynid/residual/road_profile.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"

namespace dynid::residual {

RoadProfile::RoadProfile(const std::vector<ingest::PreprocessedSegment>& segments,
                         double sample_period, double knot_spacing_m, double held_out_block_s)
    : spacing_(knot_spacing_m) {
  if (!(knot_spacing_m > 0.0) || !std::isfinite(knot_spacing_m))
    throw InputError("road profile: knot spacing " + std::to_string(knot_spacing_m) +
                     " m is not positive");
  double travelled = 0.0;
  double duration = 0.0;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const ingest::PreprocessedSegment& seg = segments[s];
    if (!seg.channels.has("vx")) throw InputError("road profile: the run has no channel 'vx'");
    const Eigen::VectorXd& vx = seg.channels["vx"];
    if (s > 0) {
      const ingest::PreprocessedSegment& prev = segments[s - 1];
      const Eigen::Index prev_end = prev.first + prev.channels.samples();
      if (seg.first < prev_end) throw InputError("road profile: segments overlap or are out of order");
      const double v_end = prev.channels["vx"](prev.channels.samples() - 1);
      travelled += 0.5 * (v_end + vx(0)) * sample_period * static_cast<double>(seg.first - prev_end + 1);
    }
    Eigen::VectorXd d(vx.size());
    for (Eigen::Index k = 0; k < vx.size(); ++k) {
      if (k > 0) travelled += 0.5 * std::abs(vx(k) + vx(k - 1)) * sample_period;
      d(k) = travelled;
    }
    distance_.push_back(std::move(d));
    duration += sample_period * static_cast<double>(vx.size());
  }
  if (duration > 0.0) spacing_ = std::max(spacing_, 2.0 * held_out_block_s * travelled / duration);
  knots_ = static_cast<Eigen::Index>(std::floor(travelled / spacing_)) + 2;
}

double RoadProfile::distance(std::size_t segment, Eigen::Index sample) const {
  return distance_.at(segment)(sample);
}

void RoadProfile::hats(double distance_m, double* out) const {
  std::fill(out, out + knots_, 0.0);
  const double at = std::clamp(distance_m / spacing_, 0.0, static_cast<double>(knots_ - 1));
  const auto left = std::min(static_cast<Eigen::Index>(std::floor(at)), knots_ - 2);
  const double t = at - static_cast<double>(left);
  out[left] = 1.0 - t;
  out[left + 1] = t;
}

std::string road_profile_effect_name(const model::Model& m) {
  bool grade = false;
  bool bank = false;
  for (const model::Effect& e : m.candidate_effects()) {
    grade = grade || e.name == model::effect::kRoadGrade;
    bank = bank || e.name == model::effect::kRoadBank;
  }
  if (grade) return "road_grade_profile";
  if (bank) return "road_bank_profile";
  return "road_profile";
}

bool is_road_profile_effect(const std::string& name) {
  return name == "road_grade_profile" || name == "road_bank_profile" || name == "road_profile";
}

}  // namespace dynid::residual
