#include "dynid/car/dropped_samples.hpp"

#include <cmath>
#include <cstdio>

#include <dynid/ingest/chunk.hpp>

#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {
namespace {

const double kLimit = ingest::ChunkLimits{}.max_abs_value;  // the server's check: one home

std::string why(double value) {
  char text[96];
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+inf" : "-inf";
  std::snprintf(text, sizeof text, "%.3g, beyond the %.0e a chunk may carry", value, kLimit);
  return text;
}

}  // namespace

bool DroppedSamples::carriable(double value) {
  return std::isfinite(value) && std::abs(value) <= kLimit;
}

bool DroppedSamples::keep(std::size_t channel, double time, double value) {
  if (carriable(value)) return true;
  Channel& c = by_channel_[channel];
  if (c.count++ == 0) c.first_time = time, c.first_value = value;
  return false;
}

std::vector<std::string> DroppedSamples::report(const VehicleProfile& profile,
                                                const std::string& where) const {
  std::vector<std::string> out;
  for (const auto& [channel, c] : by_channel_) {
    char at[64];
    std::snprintf(at, sizeof at, "%.3f", c.first_time);
    const std::string name =
        channel < profile.channels.size() ? profile.channels[channel].channel : "?";
    out.push_back("channel '" + name + "': " + std::to_string(c.count) +
                  (c.count == 1 ? " sample" : " samples") + " left out (the first " +
                  why(c.first_value) + ", at " + at + " s of " + where +
                  "'s clock); the rows around them come from the other samples or are a gap");
  }
  return out;
}

}  // namespace dynid::car
