#pragma once
// Per-run nuisance parameters, eliminated before runs are pooled.
//
// Some columns are constants of one run, not of the car: a sensor's offset drawn again at every
// power-up (the ECU's engine-torque offset T0 of clutch_slip's engine_torque_offset effect,
// model::Effect::per_run). Within a run such a column is identified with the rest; across runs
// its value differs, so merging runs accumulator by accumulator (the union of their rows, one
// shared T0) fits one mean offset to rows that have different ones, and the misfit goes into
// the friction columns. On the reference simulator, a launch run merged with a controlled-slip
// run (offsets sigma 3 N m each) gave the Coulomb level -20..+15 % with the seed.
//
// eliminate_per_run() makes of one run's accumulators those of its rows projected orthogonally
// to the nuisance columns: exactly what the run says about the other parameters whatever its
// offsets (in R_aug terms: the nuisance columns moved to the front, re-triangularized, their
// rows and columns dropped). The eliminated columns are zero in the result, so the parameter
// layout is unchanged: merge as before, and the estimate reports them as eliminated (no value:
// a pooled problem has one offset per run, none for the car). Each eliminated column takes one
// degree of freedom from its group's row count (r - k), so sigma^2 = ||rho||^2 / (r - k - n_B)
// over the pooled rows is the one of a batch solve with one offset column per run.
//
// Contract: columns must be distinct, in [0, n); a group with no rows stays empty. Throws
// InputError otherwise, or for an accumulator with forgetting (its effective row count is not
// its row count: the projection would have to carry the weights). Cost O(n^3) per group.
#include <Eigen/Core>
#include <vector>

#include "dynid/ls/equation_groups.hpp"

namespace dynid::ingest {

ls::EquationGroups eliminate_per_run(const ls::EquationGroups& run, const std::vector<Eigen::Index>& columns);

}  // namespace dynid::ingest
