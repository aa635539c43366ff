#pragma once
// VehicleProfile: everything the car side knows about one vehicle, read from a TOML file:
// its id, its DBC, which buses to listen to, the grid, how DBC signals become catalogue channels
// (docs/CHANNELS.md) in SI units, the vehicle's constants and model list for the server, and the
// spool. Profiles, not code, describe a car.
//
// The format, every key with its limits, and what is refused: docs/PROFILES.md
// (deploy/profiles/rav4.toml is a complete example).
//
// Value of a channel sample: sign * scale / divide_by * combine_i(conv_i(dbc_value_i)), where
// conv_i converts signal i from its DBC unit to the channel's SI unit. All signals of a channel
// come from one message, so they share a timestamp and combining them needs no resampling.
//
// Contract: load_vehicle_profile() reads only a regular file (input/input_file.hpp: a FIFO,
// directory or device is refused naming it), parses the DBC it names (the same) and checks every
// reference against it. Every error throws InputError "<profile file>:<line>:<column>: <key>:
// <reason>" (line and column when the key exists), for: a vehicle id that breaks the id rule
// (input/ids.hpp), TOML syntax, missing keys and wrong types, unknown or
// duplicate channel, unknown DBC message or signal, a DBC signal no frame can carry (a
// multiplexer value its switch cannot hold: can::Signal::never_present), a DBC that cannot be
// read, a missing unit
// (empty DBC unit for a dimensioned channel and no dbc_unit/factor), an unconvertible unit,
// a non-finite or non-positive number where one is required, an unknown model or a model whose
// constants it rejects, an unknown constant name in scale/divide_by; in [[sources]]: a name that
// breaks the id rule or repeats, an unknown type or time unit, a source channel without a unit
// or with one of another quantity, a channel given by two sources, a bus channel given by a
// source without replaces_bus, a clock that is neither an offset nor an estimate from a channel
// of the source against a bus channel.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <dynid/can/dbc.hpp>
#include <dynid/ingest/run_announcement.hpp>
#include <dynid/model/constants.hpp>

#include "dynid/car/resampler.hpp"
#include "dynid/car/units.hpp"

namespace dynid::car {

enum class Combine { Sum, Mean };

struct SignalInput {
  std::string signal;
  std::size_t index = 0;        ///< in can::Message::signals
  std::string dbc_unit;         ///< the unit converted from ("" with an explicit factor)
  LinearConversion to_si;       ///< DBC physical value -> channel SI unit
};

struct ChannelMapping {
  std::string channel;  ///< catalogue name
  std::string unit;     ///< its SI unit (catalogue)
  std::string message;  ///< DBC message name
  const can::Message* dbc_message = nullptr;  ///< into VehicleProfile::dbc
  std::vector<SignalInput> inputs;
  Combine combine = Combine::Sum;
  double gain = 1.0;    ///< sign * scale / divide_by
  std::optional<double> max_gap;  ///< seconds; unset: derived from the signal's period
  Interpolation interpolation = Interpolation::kLinear;  ///< between frames (resampler.hpp)
  /// Set for a channel of an auxiliary source (with_sources()): index into
  /// VehicleProfile::sources and into its channels; the bus decoder never sees it.
  std::optional<std::size_t> source;
  std::size_t source_channel = 0;
  /// Set for a channel the profile gives as one value in its SI unit (`constant = 3.5`: a gear
  /// ratio of a run in one gear, a flat track's road_grade): no DBC message or signal, and every
  /// frame that carries a channel of the profile carries the value too (signal_mapper.hpp), so
  /// the channel is valid while the bus is alive; it has no gap rule of its own (max_gap is the
  /// longest allowed), so a row's validity is that of the measured channels.
  std::optional<double> constant;

  /// The channel value from the message's decoded physical values (indexed like
  /// can::Message::signals).
  double value(const std::vector<double>& physical_by_signal) const;
};

/// One column of an auxiliary source mapped to a catalogue channel.
struct SourceChannel {
  std::string column;          ///< the header's column; for a derived channel, its quantity
  std::string derived;         ///< "" (a column), "grade" or "speed" (from the source's ECEF pose)
  std::string channel;
  std::string unit;            ///< the catalogue's SI unit
  std::string given_unit;      ///< the column's unit as the profile gives it
  LinearConversion to_si;
  double gain = 1.0;           ///< sign * scale
  std::optional<double> max_gap;
  Interpolation interpolation = Interpolation::kLinear;  ///< a second bus's mapping may set it
  bool replaces_bus = false;
};

/// How a source's clock relates to the bus: bus time = source time + offset.
struct SourceClockRelation {
  std::optional<double> offset;   ///< fixed; else estimated:
  std::string estimate_from;      ///< a channel of this source
  std::string reference;          ///< a bus channel of the profile ([[channels]])
  bool reference_derivative = false;  ///< compare with d(reference)/dt (speed against acceleration)
  double max_offset = 2.0;        ///< seconds searched either way
};

struct VehicleProfile;

struct AuxiliarySourceSpec {
  std::string name;
  std::string type;               ///< "csv", "mdf4" or "can"
  std::filesystem::path file;     ///< empty: given per run (--source NAME=FILE)
  std::string time_column;        ///< csv
  double time_scale = 1.0;        ///< csv: source time unit -> seconds
  /// csv: ECEF position (m) and velocity (m/s) columns, x y z, for derived channels
  struct Ecef {
    std::array<std::string, 3> position;
    std::array<std::string, 3> velocity;
  };
  std::optional<Ecef> ecef;
  /// can: a second bus's log with its own DBC: the DBC, interfaces and channel mappings (in
  /// the order of `channels`), decoded as the main bus's are.
  std::shared_ptr<const VehicleProfile> bus;
  SourceClockRelation clock;
  /// csv, live runs: seconds the bus may be held for this source's rows (live_merge.hpp)
  double wait = 1.0;
  std::vector<SourceChannel> channels;
};

/// Longest [[sources]] wait: every frame of the bus may be held that long.
inline constexpr double kMaxSourceWait = 30.0;

struct VehicleProfile {
  std::filesystem::path source;  ///< the profile file (or the name given to parse)
  std::string vehicle;
  std::filesystem::path dbc_path;
  std::shared_ptr<const can::Database> dbc;
  std::vector<std::string> interfaces;  ///< empty: every interface
  double rate_hz = 0.0;
  std::size_t chunk_rows = 0;
  double max_gap_periods = 2.5;
  double max_time_jump = 10.0;  ///< seconds (TimeJumpLimits::forward)
  std::vector<ChannelMapping> channels;  ///< the column order of every chunk
  /// Declared auxiliary sources; their channels join `channels` only for a run that gives them
  /// (with_sources(), auxiliary.hpp): a profile as loaded maps the bus alone.
  std::vector<AuxiliarySourceSpec> sources;
  model::Constants constants;
  std::vector<ingest::ModelSpec> models;
  std::filesystem::path spool_directory;
  std::uint64_t spool_max_bytes = 0;
  /// [preprocessing]: carried in every run's announcement to the server (defaults: DYCARO's).
  ingest::Preprocessing preprocessing;
  /// What loads but is likely a mistake, "<file>:<line>:<column>: <key>: <why>": a constant that
  /// no model of the profile reads (model/model_needs.hpp) and no channel's gain names, or a
  /// catalogue channel's name given as a constant (constants never stand in for a channel).
  std::vector<std::string> warnings;

  bool accepts_interface(std::string_view name) const;
  /// The announcement of a run of this vehicle (channels with units, rate, models).
  ingest::RunAnnouncement announcement(const std::string& run) const;
};

/// The models of a run's profile (the bus channels and those of the sources given for the run:
/// auxiliary.hpp) that the server could not run for want of a channel, by the server's own rule
/// (ingest/model_channels.hpp: derived d_<x> count when <x> is a channel; constants never stand
/// in for one): one line each, "models[i] '<name>' needs ..., which this run does not have",
/// with the optional channels it also lacks and the declared sources not given that have them.
/// Empty when every model can run. dynid-car refuses such a run before anything is sent.
std::vector<std::string> models_lacking_channels(const VehicleProfile& profile);
/// The line of models_lacking_channels for profile.models[i], empty when it can run.
std::string lacking_channels(const VehicleProfile& profile, std::size_t i);

VehicleProfile load_vehicle_profile(const std::filesystem::path& path);
/// Parses profile text; `source` names it in messages and relative paths resolve against its
/// parent folder.
VehicleProfile parse_vehicle_profile(std::string_view text, const std::filesystem::path& source);

}  // namespace dynid::car
