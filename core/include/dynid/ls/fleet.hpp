#pragma once
// Fleet estimate: least squares pooled over vehicles that share some parameters (issue 4).
//
// Vehicle v contributes its accumulated, DYCARO-weighted factor R_v (EquationGroups: each
// group's rows scaled by 1/sigma_j of the group's own fit, equation_groups.hpp) over its own
// model's parameters. Its columns split into the shared ones S (one unknown for the whole
// fleet) and its local ones L_v (unknowns of v only). The fleet system stacks, for every v,
//
//     [ 0 .. R_v(:, L_v) .. 0 | R_v(:, S) ] x = z_v          (rho_v enters the residual only)
//
// a sparse block-angular ("arrow") matrix: sum(n_v) rows, sum(|L_v|) + |S| columns. It is
// solved by SuiteSparseQR on columns scaled to unit norm, locals first and shared last (the
// order that keeps R block-angular too: no fill between vehicles). No dense stack is formed;
// the result equals a dense weighted batch solve of all raw rows to rounding error (the R_v
// are exact factors of those rows).
//
// Statistics, as estimate.hpp over the whole fleet:
//   sigma^2 = (sum_v ||rho_v||^2 + ||sparse residual||^2) / (r - rank), r = all rows,
//   std_j   = sigma sqrt(((R^T R)^-1)_jj): only that diagonal is computed, one sparse
//             triangular solve per column.
// The per-vehicle residual RMS is unweighted (the vehicle's own rows at the fleet solution).
//
// Rank. A column whose norm is negligible (BaseParameterOptions::zero_tolerance, never below
// tau = r * epsilon on unit-norm columns) is kEliminated: nobody excites it. The rest goes to
// SuiteSparseQR with tolerance tau in fixed column order (locals, then shared): a column whose
// part orthogonal to the ones before it is below tau is kDependent. Eliminated and dependent
// columns get NaN values and std; the others are estimated as the basic solution, and
// rank_deficient() says the values are then conditional on the unidentified columns being 0.
// Unlike estimate.hpp, regrouping relations are not computed for the fleet.
//
// Errors: InputError (nothing computed) for no member, an empty or duplicate vehicle id, a
// member whose parameter names do not match its groups' width or repeat, a shared name that is
// empty, repeated, or missing from a member, a shared name with different units across members,
// or a member with no rows.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "dynid/ls/base_parameters.hpp"
#include "dynid/ls/equation_groups.hpp"
#include "dynid/ls/estimate.hpp"

namespace dynid::ls {

struct FleetParameter {
  std::string name;
  std::string unit;
};

/// One vehicle: its model's parameters (the columns of `groups`) and its accumulated groups
/// (one run's, or several runs' merged group by group).
struct FleetMember {
  std::string vehicle;
  std::vector<FleetParameter> parameters;
  EquationGroups groups;
};

struct FleetParameterEstimate {
  std::string vehicle;  ///< empty for a shared parameter
  std::string name;
  std::string unit;
  double value = 0.0;               ///< NaN unless identified
  double standard_deviation = 0.0;  ///< NaN unless identified
  ParameterStatus status = ParameterStatus::kIdentified;  ///< kIdentified/kDependent/kEliminated
};

struct FleetVehicleStatistics {
  std::string vehicle;
  std::uint64_t rows = 0;
  double residual_rms = 0.0;  ///< unweighted: sqrt(sum_groups ||W_g x_v - y_g||^2 / rows)
  std::vector<GroupStatistics> groups;  ///< weights used (residual_rms at the fleet solution)
};

struct FleetEstimate {
  /// Shared parameters first (in the order asked), then each member's locals in its order.
  std::vector<FleetParameterEstimate> parameters;
  std::vector<FleetVehicleStatistics> vehicles;  ///< in member order
  double residual_norm = 0.0;  ///< of the weighted fleet system
  double sigma = 0.0;          ///< of the weighted fleet system (close to 1); NaN when dof <= 0
  std::uint64_t rows = 0;      ///< raw rows of all members
  std::uint64_t sparse_rows = 0;     ///< rows of the stacked sparse system (sum of n_v)
  Eigen::Index unknowns = 0;         ///< |S| + sum |L_v|
  Eigen::Index rank = 0;
  double degrees_of_freedom = 0.0;  ///< rows - rank
  double tolerance = 0.0;           ///< tau used on unit-norm columns

  bool rank_deficient() const { return rank < unknowns; }
};

/// Solves the fleet system (see above). `options.base` sets epsilon and zero_tolerance, and the
/// per-vehicle group weighting uses the same options as EquationGroups::estimate.
FleetEstimate fleet_estimate(const std::vector<FleetMember>& members,
                             const std::vector<std::string>& shared_parameter_names,
                             const EstimateOptions& options = {});

}  // namespace dynid::ls
