#pragma once
// Signal delays: a channel recorded late (or early) against the others (issue 15: "a steering
// signal 80 ms late"). The effect `delay:<channel>@<ms>ms` reads the channel (and its
// derivative d_<channel>) `ms` later on the run's grid, i.e. the recording lags the physics by
// that long (negative: it leads). It adds no column: the model's rows are built on the shifted
// channel, so its parameters are what they would be with the signal on time. Samples whose
// shifted source lies outside their segment are left out (invalid).
//
// The screen (effect_screen.hpp) tests a delay of every channel the model's physics reads with
// the score (Lagrange multiplier) test at zero delay: the column d r / d L, the residual's
// change per sample of delay at the declared solution (central difference of the rows built
// one sample early and one late), tested like any added column (HAC Wald, held out). A
// significant delay is then located by searching the raw grid within +-max_ms for the least
// in-sample residual, and offered under its name (delay:steer@80ms); its standard deviation is
// the score column's coefficient's at the delay found.
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"

namespace dynid::residual {

struct SignalDelay {
  std::string channel;
  Eigen::Index samples = 0;  ///< > 0: the recording is late by this many grid samples
};

bool is_delay_effect(const std::string& name);

/// Parses delay:<channel>@<ms>ms on a grid of `sample_rate_hz` (rounded to a sample).
/// InputError naming the effect when the form or the number is wrong.
SignalDelay parse_delay_effect(const std::string& name, double sample_rate_hz);

/// The effect's name for `samples` of delay on that grid.
std::string delay_effect_name(const std::string& channel, Eigen::Index samples, double sample_rate_hz);

/// The run with each delayed channel (and its d_ derivative) read `samples` later. InputError
/// when a delayed channel is not in the run.
std::vector<ingest::PreprocessedSegment> delayed(const std::vector<ingest::PreprocessedSegment>& run,
                                                 const std::vector<SignalDelay>& delays);

}  // namespace dynid::residual
