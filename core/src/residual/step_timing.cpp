#include "dynid/residual/step_timing.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace dynid::residual {
namespace {

// Increment i (from sample i to i+1) of x.
double increment(const Eigen::VectorXd& x, Eigen::Index i) {
  return x(i + 1) - x(i);
}

// The median of the increments 2 to 5 away from first..last on either side: the slope outside
// them. Eight values, so a step spread over up to three increments (two of them among one
// side's) leaves it clean; for a smooth signal the middle two are symmetric about the gap, so
// its slope and curvature cancel.
double slope_outside(const Eigen::VectorXd& x, Eigen::Index first, Eigen::Index last) {
  std::array<double, 8> around{};
  for (Eigen::Index k = 0; k < 4; ++k) {
    around[static_cast<std::size_t>(k)] = increment(x, first - 2 - k);
    around[static_cast<std::size_t>(4 + k)] = increment(x, last + 2 + k);
  }
  std::sort(around.begin(), around.end());
  return 0.5 * (around[3] + around[4]);
}

// Samples i-5 .. i+6 valid: increment i and those its slope is taken from exist.
bool looked_at(const std::vector<std::uint8_t>& valid, Eigen::Index i) {
  for (Eigen::Index k = i - 5; k <= i + 6; ++k)
    if (valid[static_cast<std::size_t>(k)] == 0) return false;
  return true;
}

// The departure made of increments first..last (flagged; of either sign: beside a ramp of four
// or more increments the slope about an increment reads the ramp and flags its flanks the other
// way, which the slope outside the whole departure puts back at zero): each increment's part
// above the slope outside them.
SampledStep step_of(const Eigen::VectorXd& x, Eigen::Index first, Eigen::Index last) {
  const double slope = slope_outside(x, first, last);
  SampledStep step;
  double weight = 0.0;
  double weighted_at = 0.0;
  double largest = 0.0;
  for (Eigen::Index i = first; i <= last; ++i) {
    const double part = increment(x, i) - slope;
    step.size += part;
    weight += std::abs(part);
    weighted_at += std::abs(part) * (static_cast<double>(i) + 0.5);
    largest = std::max(largest, std::abs(part));
  }
  step.centre = weighted_at / weight;
  step.span = weight / largest;
  return step;
}

// Of the departures found, the steps the sampling blurs: the frame interval is the channel's
// sharpest one's span (a step is spread over one frame interval, whatever its size); a departure
// spread over more than that and one grid interval of phase is a ramp the samples resolve, whose
// time they hold. Every step's time is uncertain over the frame interval.
std::vector<SampledStep> sampled_steps_only(std::vector<SampledStep> found) {
  if (found.empty()) return found;
  double frame = found.front().span;
  for (const SampledStep& s : found) frame = std::min(frame, s.span);
  std::vector<SampledStep> out;
  for (SampledStep& s : found) {
    if (s.span > frame + 1.0) continue;
    s.span = frame;
    out.push_back(s);
  }
  return out;
}

}  // namespace

std::vector<SampledStep> find_steps(const Eigen::VectorXd& x,
                                    const std::vector<std::uint8_t>& valid, double sigma) {
  std::vector<SampledStep> out;
  if (!(sigma > 0.0) || x.size() < 12 || valid.size() != static_cast<std::size_t>(x.size()))
    return out;
  const double bound = kStepSigmas * sigma * std::sqrt(2.0);
  // The outside slope of a step is read up to five increments past its last one.
  const Eigen::Index end = x.size() - 6;
  Eigen::Index first = -1;  // of the flagged increments of the departure being gathered
  for (Eigen::Index i = 5; i <= end; ++i) {
    double departure = 0.0;
    if (i < end && looked_at(valid, i)) departure = increment(x, i) - slope_outside(x, i, i);
    const bool flagged = std::abs(departure) > bound;
    if (first >= 0 && !flagged) {
      const SampledStep step = step_of(x, first, i - 1);  // looked_at(i - 1): its outside exists
      if (std::isfinite(step.span))
        out.push_back(step);  // no part left above the outside slope: none
      first = -1;
    }
    if (flagged && first < 0) first = i;
  }
  return sampled_steps_only(std::move(out));
}

void add_step_timing(const std::vector<SampledStep>& steps, std::mt19937_64& rng,
                     Eigen::VectorXd& x) {
  std::uniform_real_distribution<double> uniform(-0.5, 0.5);
  for (const SampledStep& s : steps) {
    const double area = s.size * s.span * uniform(rng);
    const auto before = static_cast<Eigen::Index>(std::floor(s.centre));
    const double after_share = s.centre - static_cast<double>(before);
    if (before >= 0 && before < x.size()) x(before) += area * (1.0 - after_share);
    if (before + 1 >= 0 && before + 1 < x.size()) x(before + 1) += area * after_share;
  }
}

}  // namespace dynid::residual
