#pragma once
// CrossValidation: how the residual loop holds data out (DESIGN.md "Residual loop").
//
// Residuals of sampled, low-passed signals are autocorrelated: an in-sample F test counts each
// of the correlated rows as independent evidence and over-claims. So every candidate is also
// judged on rows it was not fitted on: the run's time axis is cut into contiguous blocks of
// `block_seconds`, block b belongs to fold b % folds, and each fold is predicted by the model
// fitted on all the other folds. Contiguous blocks keep the correlated neighbours of a held-out
// row out of its training set, except at the block edges.
namespace dynid::residual {

struct CrossValidation {
  int folds = 5;               ///< >= 2
  double block_seconds = 5.0;  ///< > 0

  /// Fold of the row at run time t (s from the run's first sample).
  int fold_of(double t) const;
  /// InputError naming the bad setting.
  void validate() const;
};

}  // namespace dynid::residual
