#pragma once
// Equation groups and DYCARO's weighted least squares (Venture 2003 §2.B.3;
// seeds/venture-2003.en.md §4.4).
//
// Rows come in groups (one model equation, for one run): each group has its own accumulator
// over the full parameter vector. The weight of group j is 1/sigma_j, where sigma_j is the
// residual standard deviation of the group's own least-squares fit with its own base
// parameters (n_bj):  sigma_j^2 = ||Y_j - W_j X^j||^2 / (r_j - n_bj).
// The global weighted solution is the QR of the stacked, scaled R_j: no raw row is needed, and
// it equals an explicit weighted batch solve of all rows to rounding error.
//
// A group that cannot be weighted from its own residual (too few rows, or fitted exactly:
// sigma_j = 0) takes the largest weight of the others (or 1 when none can be weighted), and is
// flagged; empty groups are left out.
#include <string>
#include <vector>

#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"

namespace dynid::ls {

struct GroupStatistics {
  std::string name;
  std::uint64_t rows = 0;
  Eigen::Index base_count = 0;  ///< n_bj: base parameters of the group alone
  double sigma = 0.0;           ///< sigma_j of the group's own fit (NaN if undefined)
  double weight = 0.0;          ///< 1/sigma_j, or the fallback (see above); 0 when empty
  bool weight_from_fallback = false;
  double residual_rms = 0.0;  ///< unweighted RMS residual of the group at the global solution
};

struct WeightedEstimate {
  Estimate estimate;  ///< of the weighted system (its sigma is close to 1)
  std::vector<GroupStatistics> groups;
  Accumulator weighted;  ///< the stacked, scaled system
};

class EquationGroups {
 public:
  /// Named groups over `parameter_count` parameters; names must be unique and non-empty. Each
  /// group's accumulator folds in `precision` (accumulator.hpp).
  EquationGroups(Eigen::Index parameter_count, std::vector<std::string> names,
                 Precision precision = Precision::kExtended);

  std::size_t size() const { return names_.size(); }
  const std::string& name(std::size_t group) const { return names_.at(group); }
  /// Index of a group by name; throws InputError naming an unknown group.
  std::size_t index_of(const std::string& name) const;
  Accumulator& group(std::size_t group) { return groups_.at(group); }
  const Accumulator& group(std::size_t group) const { return groups_.at(group); }

  /// Folds rows into one group (same contract as Accumulator::fold).
  void fold(std::size_t group, const Eigen::Ref<const Eigen::MatrixXd>& W,
            const Eigen::Ref<const Eigen::VectorXd>& y);

  /// The weighted estimate. Throws InputError when no group has rows.
  WeightedEstimate estimate(const EstimateOptions& options = {}) const;

 private:
  std::vector<std::string> names_;
  std::vector<Accumulator> groups_;
};

}  // namespace dynid::ls
