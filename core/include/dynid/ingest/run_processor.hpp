#pragma once
// RunProcessor: the server's processing of one vehicle-run, chunk by chunk (DYCARO's
// script_filtre -> script_obs -> script_ident, streamed). One per run; DDS-free.
//
// Pipeline. Every chunk is validated (validate_chunk unless it comes as a ValidatedChunk of this
// run under the same limits, then sequence and grid continuity); its
// valid samples go through one StreamingZeroPhaseFilter per valid segment (all channels but the
// announcement's `unfiltered` ones, which are delayed to stay aligned), the `d_<name>` channels
// that the models need and the run does not measure come from a StreamingDerivative of the
// filtered `<name>`, and each model's rows are built on the samples that became final and lie on
// the decimation grid (run sample index % preprocessing.odmf == 0: DYCARO's decimation after
// the zero-phase low-pass, run_announcement.hpp) and folded into its ls::EquationGroups (one
// accumulator per model equation group).
//
// Segments. A gap (valid == 0) ends the current valid segment; the next valid sample starts a
// new one with a fresh filter. Each segment is processed as the offline filter processes a whole
// record: odd extension and steady-state starts at both of its ends (zero_phase_filter.hpp),
// one-sided second-order differences at its first and last samples (derivative.hpp), model
// rows whose lags or look-ahead reach outside the segment are left out, as at a run's ends
// (effects.hpp), and so are the rows within the filter's edge reach of either end
// (Preprocessing::edge_samples: there the filtered samples are partly the edge extension).
// Nothing is ever filtered across a gap. A segment of at most padlen samples
// (too short for the edge extension) is skipped and counted (RunCounters::short_segments).
//
// Invariance. The result does not depend on how the run is cut into chunks: the streaming
// filter's output is bit-identical for any chunking (its backward sweeps start on a grid fixed
// by the sample index within the segment), derivatives are exact, and rows are built with the
// context and look-ahead their model reads (model::Model::reach(), at least kReachBack and
// kReachAhead), so each row is the same bits as in a one-chunk run; which rows are folded
// depends on the grid index only. Only the grouping of rows into accumulator folds differs,
// i.e. the estimates agree to rounding (extended-precision accumulators: ~1e-15 relative).
//
// Delay: a sample's rows are folded once about filter delay() + 1 + the larger of the models'
// look-ahead and the edge reach later samples are in; finish() folds the rest.
//
// Checkpoints. checkpoint() is the complete state (accumulators, filter and derivative buffers,
// the row window, counters, sequence), versioned and checksummed; restore() under the same
// announcement continues the run so that restore + the remaining chunks gives accumulators
// bit-identical to an uninterrupted run.
//
// Cost: state O((overlap + block) x channels + sum of n^2 over model groups); per chunk, work
// linear in its samples; no allocation per row (buffers are per chunk or reused).
//
// Errors (strong guarantee: a rejected call changes no state, so the caller can count it and go
// on): push() throws InputError for an invalid chunk, a sequence other than next_sequence(), a
// first_sample_index other than next_sample_index() (after the first chunk), after finish(), or
// when a model rejects the data (a non-finite row at a sample it folds: the reason names the
// model and sample; rows are built only on the decimation grid, see Pipeline).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/ingest/validated_chunk.hpp"
#include "dynid/ls/equation_groups.hpp"
#include "dynid/model/model.hpp"
#include "dynid/signal/held_buffer.hpp"
#include "dynid/signal/sos.hpp"

namespace dynid::ingest {

/// Least row context around a sample: the dictionary's lags (3 back) and look-ahead (its
/// five-point difference: 2 ahead; locked driveline's neighbour test: 1); a model that reads
/// further says so (model::Model::reach()) and gets more. (The edge reach, Preprocessing::
/// edge_samples, is a look-ahead too: rows are built once it is in.)
inline constexpr Eigen::Index kReachBack = 3;
inline constexpr Eigen::Index kReachAhead = 2;

struct RunCounters {
  std::uint64_t chunks = 0;           ///< chunks accepted
  std::uint64_t samples = 0;          ///< grid samples received
  std::uint64_t invalid_samples = 0;  ///< samples in gaps
  std::uint64_t segments = 0;         ///< valid segments processed to their end
  std::uint64_t short_segments = 0;   ///< valid segments skipped: too short to filter
  std::uint64_t short_segment_samples = 0;
  std::uint64_t final_samples = 0;  ///< preprocessed samples handed to the models
};

/// A model of the run and its estimate.
struct ModelEstimate {
  std::string model;                             ///< registry name
  std::vector<model::ParameterInfo> parameters;  ///< columns: parameters, then effects'
  std::vector<std::string> groups;
  std::vector<std::uint64_t> group_rows;
  /// The weighted estimate (values, std, statuses in estimate.structure.status); empty when
  /// the model is not run or has no row yet, `note` says which.
  std::optional<ls::WeightedEstimate> estimate;
  std::string note;
};

class RunProcessor {
 public:
  /// Validates the announcement, builds its models (InputError for an unknown model, a bad
  /// constant, an unknown effect or a channel in the wrong unit). A model whose channels the
  /// run does not carry is kept, not run, with the reason in its estimate's note.
  explicit RunProcessor(RunAnnouncement announcement, ChunkLimits limits = {});
  ~RunProcessor();
  RunProcessor(RunProcessor&&) noexcept;
  RunProcessor& operator=(RunProcessor&&) noexcept;

  void push(const Chunk& chunk);
  /// push() of a chunk the caller has validated already (the server validates each chunk as
  /// it arrives, before storing it): validate_chunk is not run again when the chunk was
  /// validated for this run's ids and channel count under this processor's limits
  /// (ValidatedChunk::validated_for), and is run again otherwise. Same errors and guarantee.
  void push(const ValidatedChunk& chunk);
  /// Ends the run: flushes the last segment. Throws InputError when already finished.
  void finish();

  std::vector<ModelEstimate> estimates(const ls::EstimateOptions& options = {}) const;

  std::string checkpoint() const;
  /// Rebuilds a processor from checkpoint() bytes. Throws InputError on corrupted, truncated or
  /// trailing bytes, another format version, or a checkpoint of another announcement.
  static RunProcessor restore(RunAnnouncement announcement, std::string_view bytes,
                              ChunkLimits limits = {});

  const RunAnnouncement& announcement() const;
  std::size_t model_count() const;
  /// The model's accumulators; nullptr when the model is not run.
  const ls::EquationGroups* groups(std::size_t model) const;
  const RunCounters& counters() const;
  std::uint64_t next_sequence() const;
  std::uint64_t next_sample_index() const;
  bool finished() const;
  /// Names and units of the derived channels made here (d_<name>), in column order.
  std::vector<std::pair<std::string, std::string>> derived_channels() const;
  /// The buffers held between pushes, for memory accounting (allocated and held bytes): the
  /// segment's ("segment ...", with what it keeps to undo a rejected push: "... mark ...",
  /// "... undo ..."), then each run model's accumulators ("<model> accumulators"). Small fixed
  /// members are not listed.
  std::vector<signal::HeldBuffer> held_buffers() const;
  /// The low-pass applied (for reports and for reproducing the processing offline).
  const signal::Sos& filter() const;

 private:
  struct Impl;
  explicit RunProcessor(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynid::ingest
