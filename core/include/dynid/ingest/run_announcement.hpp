#pragma once
// RunAnnouncement: what a car says before it streams a run, and what the server needs to
// process it: the channel layout of every chunk, the grid rate, and the model profile (which
// models to run with which constants and effects). Transport-neutral: the DDS type in idl/
// mirrors it and server/client translate at their edge.
//
// Contract: validate() throws InputError naming the field and the reason for an empty vehicle or
// run id, a non-positive or non-finite sample rate, no channel, a duplicate or empty channel
// name, a model spec without a name, a non-finite constant.
#include <map>
#include <string>
#include <vector>

namespace dynid::ingest {

struct ChannelSpec {
  std::string name;  ///< from docs/CHANNELS.md
  std::string unit;  ///< SI, as in docs/CHANNELS.md
};

struct ModelSpec {
  std::string model;                        ///< registry name, e.g. "lateral_bicycle"
  std::map<std::string, double> constants;  ///< the vehicle profile's constants for it
  std::vector<std::string> effects;         ///< enabled candidate effects
};

struct RunAnnouncement {
  std::string vehicle;  ///< vehicle id, e.g. "proto-17"
  std::string run;      ///< run id, unique per vehicle
  double sample_rate_hz = 0.0;
  std::vector<ChannelSpec> channels;  ///< column order of every chunk
  std::vector<ModelSpec> models;

  void validate() const;
  /// Index of a channel's column; throws InputError naming an unknown channel.
  std::size_t column_of(const std::string& channel) const;
};

}  // namespace dynid::ingest
