#pragma once
// VehicleProfile: everything the car side knows about one vehicle, read from a TOML file:
// its id, its DBC, which buses to listen to, the grid, how DBC signals become catalogue channels
// (docs/CHANNELS.md) in SI units, the vehicle's constants and model list for the server, and the
// spool. Profiles, not code, describe a car.
//
// Format (deploy/profiles/rav4.toml is a complete example):
//
//   [vehicle]
//   id = "rav4-2017"
//   dbc = "../../dbc/toyota.dbc"       # relative to this profile file
//   interfaces = ["can0"]              # optional: frames from other buses are ignored
//   [grid]
//   rate_hz = 50.0                     # uniform grid of every run, at most 10 kHz
//   chunk_seconds = 1.0                # a whole number of grid periods, at most 10000 rows
//   max_gap_periods = 2.5              # optional (1..3600): see resampler.hpp
//   max_time_jump = 10.0               # optional (seconds, at most 3600): a jump of the frames'
//                                      # clock, or a bus silence, longer than this ends the
//                                      # grid piece (source_clock.hpp, resampler.hpp)
//   [spool]
//   directory = "spool"                # relative to this profile file unless absolute
//   max_bytes = 1073741824
//   [constants]                        # SI, shared by every model
//   wheel_radius = 0.33
//   [[models]]
//   name = "longitudinal_engine"       # model registry name
//   effects = ["road_grade"]           # optional
//   constants = { driveline_efficiency = 0.9 }   # optional, added to / override [constants]
//   [preprocessing]                    # optional; every key defaults to the server's (DYCARO's)
//   butterworth_order = 5              # zero-phase low-pass order, 1..8
//   cut_off_hz = 5.0                   # -3 dB, below rate_hz / 2; absent: 0.8 rate_hz / (2 odmf)
//   odmf = 8                           # rows on every odmf-th grid sample (decimation), 1..1000
//   noise = { ax = 0.05 }              # declared sensor noise std per channel (its SI unit),
//                                      # used by the residual loop's noise floor instead of
//                                      # measuring it above the cut-off
//   [[channels]]
//   name = "vx"                        # catalogue channel; its SI unit comes from the catalogue
//   message = "WHEEL_SPEEDS"           # DBC message name
//   signals = ["WHEEL_SPEED_FL", "WHEEL_SPEED_FR", "WHEEL_SPEED_RL", "WHEEL_SPEED_RR"]
//   combine = "mean"                   # "sum" (default) or "mean" of the converted signals
//   # optional: signal = "X" (one signal), dbc_unit = "bar" (when the DBC has none or a wrong
//   # one), factor/offset (explicit DBC -> SI conversion instead of the unit table), scale and
//   # divide_by (a number or the name of a [constants] entry, e.g. "steering_ratio"),
//   # sign = -1, max_gap (seconds, at most 3600, instead of the derived window),
//   # interpolation = "cubic" (a smooth signal on a slower message: the grid's values between
//   # frames without linear interpolation's attenuation; "linear", the default, for a signal that
//   # steps, resampler.hpp).
//
//   [[sources]]                        # optional: auxiliary sources besides the bus (auxiliary.hpp)
//   name = "recorder_imu"              # the id rule (input/ids.hpp); dynid-car --source NAME=FILE
//   type = "csv"                       # a time-stamped CSV file, one header line
//   file = "imu.csv"                   # optional, relative to this profile; --source overrides
//   time_column = "t"
//   time_unit = "s"                    # s, ms, us or ns
//   clock = { offset = 0.0 }           # bus time = source time + offset (seconds), or
//   clock = { estimate_from = "ax", reference = "ax", max_offset = 2.0, reference_derivative = false }
//   wait = 1.0                         # live runs: seconds the bus may wait for this source's
//                                      # rows (live_merge.hpp), at most 30
//   [[sources.channels]]
//   column = "ax"                      # a column of the header
//   channel = "ax"                     # catalogue channel
//   unit = "m/s^2"                     # required: the column's unit, converted to the channel's
//   # optional: scale, sign = -1, max_gap (as for bus channels), replaces_bus = true (the bus
//   # mapping of this channel gives way when the source is given for a run)
//   # A GNSS/INS pose in ECEF (WGS84) gives derived channels (ecef.hpp):
//   ecef = { position = ["x", "y", "z"], velocity = ["vx", "vy", "vz"] }   # m and m/s columns
//   [[sources.channels]]
//   derived = "grade"                  # the path's slope (rad; none below 1 m/s), or "speed" (m/s)
//   channel = "road_grade"             # a channel of that unit; no column, no unit
//   [[sources]]                        # a second CAN log (candump, ASC, BLF) with its own DBC
//   name = "chassis"
//   type = "can"
//   dbc = "chassis.dbc"                # relative to this profile
//   interfaces = ["can1"]              # optional, as [vehicle] interfaces
//   file = "chassis.blf"               # optional; --source chassis=FILE
//   clock = { offset = 0.0 }           # as above
//   [[sources.channels]]               # written as [[channels]] are, plus replaces_bus
//   name = "roll_rate"
//   message = "IMU2"
//   signal = "RollRate"
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
// duplicate channel, unknown DBC message or signal, a DBC that cannot be read, a missing unit
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
  std::string type;               ///< "csv" or "can"
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

  bool accepts_interface(std::string_view name) const;
  /// The announcement of a run of this vehicle (channels with units, rate, models).
  ingest::RunAnnouncement announcement(const std::string& run) const;
};

VehicleProfile load_vehicle_profile(const std::filesystem::path& path);
/// Parses profile text; `source` names it in messages and relative paths resolve against its
/// parent folder.
VehicleProfile parse_vehicle_profile(std::string_view text, const std::filesystem::path& source);

}  // namespace dynid::car
