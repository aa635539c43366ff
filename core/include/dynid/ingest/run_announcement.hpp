#pragma once
// RunAnnouncement: what a car says before it streams a run, and what the server needs to
// process it: the channel layout of every chunk, the grid rate, and the model profile (which
// models to run with which constants and effects). Transport-neutral: the DDS type in idl/
// mirrors it and server/client translate at their edge.
//
// Contract: validate() throws InputError naming the field and the reason for a vehicle id or
// run name that breaks the id rule (input/ids.hpp; the ids are shown escaped), a non-positive or non-finite sample rate, no channel, a duplicate or empty channel
// name, a model spec without a name, a non-finite constant, preprocessing settings out of range
// (Butterworth order outside 1..8, a cut-off not strictly inside (0, fs/2), odmf < 1 (also with
// an explicit cut-off: odmf is the decimation factor of the rows), a filter
// tolerance outside [1e-13, 1e-3]).
//
// encode_announcement()/decode_announcement() are an exact, versioned, checksummed binary form
// (little-endian); the server stores it and a run checkpoint carries its checksum, so a
// checkpoint is never restored under another announcement.
#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
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

/// How the server preprocesses the run (DYCARO's script_filtre; venture-2003 §4.3): every
/// channel but the `unfiltered` ones goes through one zero-phase Butterworth low-pass, the
/// `d_<name>` channels the models need are its central differences, and the model rows are
/// built on every odmf-th sample ("parallel filtering/decimation"). Defaults follow the
/// source's settings (order 5; cut-off 0.8 fs / (2 odmf), i.e. 0.8 of the decimated Nyquist
/// frequency, so the rule and the decimation agree).
///
/// Why decimate: after a low-pass at f_c the samples are correlated over ~1 / (2 f_c); rows at
/// the full rate add no information but make the reported standard deviations optimistic by
/// about sqrt(fs / (2 f_c)) (about 3 at 100 Hz and 5 Hz: docs/ACCURACY.md). The filter and the
/// derivatives run at the full rate (the derivative of a decimated signal would be coarser);
/// only the rows are decimated, on the run's sample grid (index % odmf == 0).
struct Preprocessing {
  int butterworth_order = 5;  ///< DYCARO's nbutter, 1..8
  double cutoff_hz = 0.0;     ///< -3 dB cut-off; 0 means DYCARO's rule 0.8 fs / (2 odmf)
  /// DYCARO's decimation factor (>= 1; 1 = a row on every sample), and the cut-off divisor
  /// when cutoff_hz == 0. With an explicit cut-off keep fs / (2 odmf) >= cutoff_hz, or the
  /// rows are still correlated (the std optimistic again).
  int odmf = 8;
  /// Bound on |streamed - offline zero-phase filter| relative to max|x| (per segment).
  double filter_tolerance = 1e-10;
  /// Channels passed through as they are (delayed to stay aligned): discrete ones, which a
  /// low-pass would smear across a gear change. Names not announced are ignored.
  std::vector<std::string> unfiltered = {"gear", "gear_ratio"};
  /// Declared sensor noise: channel -> white-noise std at the grid rate, in the channel's unit
  /// (finite, > 0; an announced channel). The residual loop's noise floor uses it instead of
  /// measuring the channel above the cut-off (residual/noise_floor.hpp). Empty: all measured.
  std::map<std::string, double> channel_noise;

  /// The cut-off actually used, Hz.
  double cutoff(double sample_rate_hz) const;
  /// Rows are built only at samples this far or farther from both ends of their valid segment:
  /// the filter's edge reach (signal::zero_phase_edge_reach) at kEdgeOutsideShare. Nearer an
  /// end, a filtered sample is partly made of the edge extension, an error that follows the
  /// signal's curvature there and repeats with the run (the second car's engine model on its
  /// simulated true channels, seed 1001: drag area +0.72 % with those rows, +0.11 % without;
  /// dynid-diag-rows). 1.75 / cut-off for the 5th order: 0.35 s at 5 Hz.
  Eigen::Index edge_samples(double sample_rate_hz) const;
};

/// The share of a row's filtered value that may come from beyond its segment's end (the edge
/// extension): 1 %, so that a kept row carries at most a hundredth of the extension's departure
/// from the signal.
inline constexpr double kEdgeOutsideShare = 0.01;

struct RunAnnouncement {
  std::string vehicle;  ///< vehicle id, e.g. "proto-17"
  std::string run;      ///< run id, unique per vehicle
  double sample_rate_hz = 0.0;
  std::vector<ChannelSpec> channels;  ///< column order of every chunk
  std::vector<ModelSpec> models;
  Preprocessing preprocessing;

  void validate() const;
  /// Index of a channel's column; throws InputError naming an unknown channel.
  std::size_t column_of(const std::string& channel) const;
};

std::string encode_announcement(const RunAnnouncement& announcement);
/// Inverse of encode_announcement(); throws InputError on truncated, corrupted (checksum) or
/// trailing bytes. The result is not validated: call validate().
RunAnnouncement decode_announcement(std::string_view bytes);

}  // namespace dynid::ingest
