#pragma once
// Auxiliary sources of a run: measured data besides the CAN bus (a data logger's IMU, a GNSS
// receiver's CSV), declared in the vehicle profile ([[sources]], vehicle_profile.hpp), given per
// run (the profile's file, or dynid-car --source NAME=FILE), put on the bus's clock and merged
// into the run's grid by the pipeline with the same gap and validity rules as bus channels
// (pipeline.hpp, resampler.hpp). docs/DESIGN.md "Auxiliary sources".
//
// CSV source: one header line naming the columns (comma-separated, blanks around a name
// ignored), then one row per time, sorted by time. An empty cell is a missing sample of that
// channel; "nan" likewise (counted, warned). Errors (InputError "<file>:<line>: <reason>",
// nothing of the file used): a column the profile names is not in the header (the header's
// columns listed), a row with another number of cells, a cell that is not a number, a time that is
// not finite, a time earlier than the row before (unsorted: the rows must be sorted by time).
// Warnings (what was done): rows repeating the previous row's time are dropped, non-finite values
// are left out. Columns the profile does not map are ignored (named in the report).
//
// MDF4 source: an ASAM MDF4 file of physical channels (CANape, INCA, asammdf, a logger's decoded
// signals). Each source channel is the file's channel its `column` names, found in whichever
// channel group holds it (an error naming the file's groups when none or several do), with its
// conversion applied, at its group's master time after the header's start: seconds since 1970,
// the clock of MDF4 and candump bus logs. The file's unit, where it differs from the profile's
// `unit`, is a warning (the profile's is used). Read whole in a replay; not followed live.
//
// Clock: bus time = source time + offset, the offset fixed in the profile or estimated
// (clock_offset.hpp) from a channel of the source against a bus channel decoded from the
// replayed log (the bus mapping, even where the source replaces it in the run). A live run has
// no log to estimate from before it starts: an estimated clock is then an error; its sources are
// followed while they are written (live_source.hpp, live_merge.hpp). A clock that
// drifts (a significant slope of the offset along the run, clock_offset.hpp) is an error: a fixed
// offset cannot align it.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynid/car/auxiliary_follower.hpp"
#include "dynid/car/clock_offset.hpp"
#include "dynid/car/frame_source.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {

/// Largest auxiliary file read (an IMU at 1 kHz for 10 hours in CSV is about 2 GB: cut such a
/// recording per run).
inline constexpr std::uintmax_t kMaxAuxiliaryFileBytes = 1ull << 30;

struct AuxiliaryTable {
  std::vector<double> time;                 ///< seconds, source clock, increasing
  std::vector<std::vector<double>> values;  ///< per source channel; NaN: no sample
  std::vector<std::string> warnings;
  std::string unmapped_columns;  ///< header columns the profile does not map (ignored)
};

AuxiliaryTable read_auxiliary_csv(const AuxiliarySourceSpec& spec, const std::filesystem::path& file);

/// A sample of an auxiliary channel on the bus's clock.
struct AuxiliarySample {
  double time = 0.0;        ///< bus clock, seconds
  std::size_t channel = 0;  ///< index into the run's VehicleProfile::channels
  double value = 0.0;       ///< SI
};

/// What was done with one declared source for this run.
struct SourceReport {
  std::string name;
  std::filesystem::path file;  ///< empty: not given, left out
  double offset = 0.0;
  std::optional<ClockEstimate> estimate;
  std::size_t samples = 0;
  bool followed = false;  ///< live: read as it is written (the merge reports its rows at the end)
  std::vector<std::string> warnings;
  std::string unmapped_columns;
  std::string describe() const;  ///< one line for the log
};

struct RunSources {
  VehicleProfile profile;  ///< the run's profile: the bus channels, those of the given sources
  std::vector<AuxiliarySample> samples;  ///< replay: every source's samples, sorted by time
  std::vector<FollowedSource> followed;  ///< live: every given source, followed as it is written
  std::vector<SourceReport> reports;
};

/// Opens a CAN source live on an interface (given as its --source NAME=INTERFACE); dynid-car
/// gives one (client/car/src/socketcan, can_interface_follower.hpp).
using LiveCanOpener =
    std::function<std::unique_ptr<LiveSource>(const AuxiliarySourceSpec&, const std::string& interface, double offset)>;

/// The run's profile and auxiliary samples. `given`: --source NAME=FILE (overrides the profile's
/// file); a name the profile does not declare is an InputError. `bus`: the replayed log, read once
/// from its start for estimated clocks (nullptr: none). `live`: a live run, whose sources are
/// followed as they are written (live_source.hpp; opened here, nothing read yet) and need a fixed
/// clock offset: a CSV source's file (auxiliary_follower.hpp), a CAN source's interface given in
/// place of its log, opened by `open_can` (none: an InputError). A declared source with no file
/// is left out of the run (reported), its replaced bus channels staying on the bus.
RunSources prepare_sources(const VehicleProfile& declared, const std::map<std::string, std::filesystem::path>& given,
                           FrameSource* bus, bool live = false, const LiveCanOpener& open_can = {});

}  // namespace dynid::car
