#pragma once
// Helpers of the residual-loop tests: a simulated run through the product's data path
// (tests/sim/sim_product_path.hpp) to preprocessed segments, and the before/after table.
#include <map>
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/sim/simulator.hpp"

namespace dynid::residual::test {

struct ProcessedRun {
  ingest::RunAnnouncement announcement;
  ingest::RecordedRun recorded;  ///< as assembled from the chunks (raw samples)
  std::vector<ingest::PreprocessedSegment> segments;
};

/// The simulated run replayed with the test car's profile (one model spec), with the tare's
/// zeros applied when `tare` is set, assembled and preprocessed offline.
ProcessedRun process(const sim::Run& run, const ingest::ModelSpec& spec, bool tare,
                     double cutoff_hz = 0.0);

/// Prints the before/after table of a comparison (parameters with std and, where known, the
/// error against the truth; residual RMS in sample and held out).
void print_comparison(const std::string& title, const EffectComparison& c);

/// Prints the top of a screen's ranking.
void print_ranking(const ScreenResult& screen, std::size_t top);

}  // namespace dynid::residual::test
