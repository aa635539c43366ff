#include "dynid/car/source_clock.hpp"

#include <cmath>
#include <string>

#include "dynid/error.hpp"

namespace dynid::car {

SourceClock::SourceClock(TimeJumpLimits limits) : limits_(limits) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(limits_.forward) || !positive(limits_.backward))
    throw InputError("source clock: the time jump limits must be positive and finite (forward " +
                     std::to_string(limits_.forward) + " s, backward " + std::to_string(limits_.backward) + " s)");
}

bool SourceClock::step(double time) {
  if (!started_) {
    started_ = true;
    first_ = newest_ = time;
    return false;
  }
  if (time > newest_ + limits_.forward || time < newest_ - limits_.backward) {
    covered_ += newest_ - first_;
    first_ = newest_ = time;
    ++jumps_;
    return true;
  }
  if (time > newest_) newest_ = time;
  return false;
}

}  // namespace dynid::car
