#include "dynid/ingest/zero_calibration.hpp"

#include <utility>

#include "dynid/error.hpp"

namespace dynid::ingest {

ZeroCalibration::ZeroCalibration(RunAnnouncement tare, std::vector<std::string> channels,
                                 std::uint64_t min_samples)
    : tare_(std::move(tare)), channels_(std::move(channels)), min_samples_(min_samples) {
  tare_.validate();
  for (const auto& c : channels_) columns_.push_back(tare_.column_of(c));
  sums_.assign(channels_.size(), 0.0L);
}

void ZeroCalibration::push(const Chunk& chunk) {
  validate_chunk(chunk, tare_);
  if (chunk.sequence != next_sequence_)
    throw InputError("tare " + tare_.vehicle + "/" + tare_.run + ": chunk #" + std::to_string(chunk.sequence) +
                     " where #" + std::to_string(next_sequence_) + " was expected");
  for (Eigen::Index k = 0; k < chunk.samples.rows(); ++k) {
    if (chunk.valid[static_cast<std::size_t>(k)] == 0) continue;
    for (std::size_t c = 0; c < columns_.size(); ++c)
      sums_[c] += static_cast<long double>(chunk.samples(k, static_cast<Eigen::Index>(columns_[c])));
    ++count_;
  }
  ++next_sequence_;
}

std::map<std::string, double> ZeroCalibration::zeros() const {
  std::map<std::string, double> out;
  for (std::size_t c = 0; c < channels_.size(); ++c) {
    if (count_ < min_samples_)
      throw InputError("tare " + tare_.vehicle + "/" + tare_.run + ": channel '" + channels_[c] + "' has " +
                       std::to_string(count_) + " valid samples, fewer than the " + std::to_string(min_samples_) +
                       " a zero needs");
    out[channels_[c]] = static_cast<double>(sums_[c] / static_cast<long double>(count_));
  }
  return out;
}

void ZeroCalibration::apply(RunAnnouncement& run) const {
  if (run.vehicle != tare_.vehicle)
    throw InputError("tare of vehicle '" + tare_.vehicle + "' applied to a run of '" + run.vehicle + "'");
  const auto z = zeros();
  for (auto& m : run.models)
    for (const auto& [channel, value] : z) m.constants[channel + "_zero"] = value;
}

}  // namespace dynid::ingest
