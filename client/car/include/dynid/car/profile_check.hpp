#pragma once
// ProfileCheck: what `dynid-car --check-profile [--replay LOG]` says before anything is sent, so
// that a test engineer writing a profile for a car learns at the desk, not after a run, which
// models it supports.
//
// Without a log: for each model of [[models]], whether it can run on the profile's channels and,
// when not, exactly why (the channels it needs that nothing maps: models_lacking_channels, the
// rule the car applies at the start of a run). A profile that does not load (a constant missing,
// a DBC name that is not there) is an InputError, as at the start of a run.
// With a log, read through the same pipeline as a run (nothing spooled or sent): per channel,
// its sample rate on the log (samples over the log's span, first frame to last), the share of rows
// it left without a value (the gap rule invalidates them: pipeline.hpp, missing_report), and its
// health findings (ingest/channel_health.hpp: constant, sentinel, out of range); per model,
// whether the log's channels let it be judged: the first blocking finding on a channel it reads
// (ingest::unhealthy_reason, the rule every server reply takes), or no valid segment at all.
//
// Contract: text() is one block for a terminal; runs() is false when any model cannot run (the
// program's exit status).
#include <string>
#include <vector>

#include "dynid/car/pipeline.hpp"
#include "dynid/car/vehicle_profile.hpp"
#include "dynid/ingest/chunk.hpp"

namespace dynid::car {

struct ChannelCheck {
  std::string channel;
  std::string unit;
  std::string source;                 ///< "MESSAGE.Signal" or the auxiliary source
  double rate_hz = 0.0;               ///< samples per second of log on the grid
  double missing_share = 0.0;         ///< of the rows
  std::vector<std::string> findings;  ///< health statements
};

struct ModelCheck {
  std::string model;
  bool runs = true;
  std::string why;  ///< empty when it runs
};

struct ProfileCheck {
  std::string vehicle;
  double grid_hz = 0.0;
  std::vector<ModelCheck> models;
  bool with_log = false;
  std::string log;       ///< its name
  double seconds = 0.0;  ///< from the log's first frame to its last
  std::uint64_t rows = 0;
  std::uint64_t invalid_rows = 0;
  std::vector<ChannelCheck> channels;
  std::vector<std::string> run_findings;  ///< run-wide (most rows invalid)

  bool runs() const;
  std::string text() const;
};

/// The check of the profile alone.
ProfileCheck check_profile(const VehicleProfile& profile);

/// Adds what a log read through `pipe` (finished) into `chunks` says (above).
void check_log(ProfileCheck& check, const VehicleProfile& profile, const std::string& log_name,
               const CarPipeline& pipe, const std::vector<ingest::Chunk>& chunks);

}  // namespace dynid::car
