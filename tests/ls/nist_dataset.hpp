#pragma once
// Reader for the NIST StRD linear-regression files (../shared/data/nist-strd/*.dat): the data,
// the certified estimates with their standard deviations and the certified residual SD, and
// the model's design matrix (intercept or not; polynomial in one predictor or linear in several).
#include <Eigen/Core>
#include <string>
#include <vector>

namespace dynid::test {

struct NistDataset {
  std::string name;
  Eigen::MatrixXd design;  ///< the regressor W, one column per certified parameter
  Eigen::VectorXd y;
  Eigen::VectorXd certified_value;
  Eigen::VectorXd certified_std;
  double certified_residual_sd = 0.0;
};

/// Parses one .dat file; throws std::runtime_error naming the file and line on a format surprise.
NistDataset read_nist_dataset(const std::string& path);

/// Log relative error: -log10(|computed - certified| / |certified|), or the log absolute error
/// when the certified value is 0; capped at 15 (agreement to all digits).
double log_relative_error(double computed, double certified);

}  // namespace dynid::test
