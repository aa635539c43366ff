#pragma once
// RecordedRun: a whole stored run (its announcement and every chunk, in order) and its offline
// preprocessing, for the analyses that need the rows themselves rather than the accumulators:
// the residual time series and the candidate-effect screen (residual/), and reports.
//
// assemble_run() lays the chunks end to end on the run's sample grid. Contract: chunks are
// validated against the announcement (validate_chunk) and must be the sequences 0, 1, 2, ...
// with contiguous sample indices; otherwise InputError naming the chunk and the reason.
//
// preprocess_offline() is DYCARO's script_filtre on the whole record, as RunProcessor's
// documentation defines it: every valid segment longer than the filter's padlen is low-passed
// whole (zero-phase, the announcement's Butterworth; the `unfiltered` channels pass through),
// and d_<name> is the central difference of the filtered <name> for EVERY announced channel the
// run does not measure itself (so that any candidate effect can read it). Segments too short to
// filter are left out, as RunProcessor leaves them out. The streamed path equals this one to the
// announcement's filter tolerance (tests/ingest: "MatchesTheFullyOfflinePath...").
//
// Rows are decimated by the caller: a row at segment sample i is built when
// (segment.first + i) % odmf == 0 and i is at least segment.edge samples from both ends of the
// segment (row_at(); Preprocessing::edge_samples()).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/model/channel_set.hpp"

namespace dynid::ingest {

struct RecordedRun {
  RunAnnouncement announcement;
  std::uint64_t first_sample_index = 0;  ///< run grid index of samples.row(0)
  Eigen::MatrixXd samples;               ///< grid samples x announced channels
  std::vector<std::uint8_t> valid;       ///< one flag per sample
};

RecordedRun assemble_run(RunAnnouncement announcement, const std::vector<Chunk>& chunks,
                         const ChunkLimits& limits = {});

struct PreprocessedSegment {
  Eigen::Index first = 0;  ///< run grid index of the segment's first sample
  model::ChannelSet channels;
  Eigen::Index edge = 0;  ///< no row within this many samples of either end (the filter's edges)
};

std::vector<PreprocessedSegment> preprocess_offline(const RecordedRun& run);

/// preprocess_offline(run) for a run that differs from the one `segments` were made from in the
/// samples of channel `column` only (same validity): every channel is filtered on its own, so
/// only that channel, and the derivative made from it, are preprocessed again; the result is
/// equal to preprocess_offline(run), at a fraction of its cost on a run of many channels (the
/// noise floor's Monte Carlo draws, residual/noise_floor.hpp).
std::vector<PreprocessedSegment> preprocess_channel_again(const RecordedRun& run,
                                                          std::vector<PreprocessedSegment> segments,
                                                          Eigen::Index column);
/// The same for `run` with channel `column`'s samples replaced by `values` (run.samples.rows()
/// of them): the noise floor's draws change one channel and copy none of the others.
std::vector<PreprocessedSegment> preprocess_channel_again(const RecordedRun& run,
                                                          std::vector<PreprocessedSegment> segments,
                                                          Eigen::Index column,
                                                          const Eigen::VectorXd& values);

/// True when a row is built at segment sample `i`: it lies on the run's decimation grid and at
/// least segment.edge samples from both ends of the segment.
inline bool row_at(const PreprocessedSegment& segment, Eigen::Index i, int odmf) {
  return (segment.first + i) % odmf == 0 && i >= segment.edge &&
         i < segment.channels.samples() - segment.edge;
}

}  // namespace dynid::ingest
