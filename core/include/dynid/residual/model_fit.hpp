#pragma once
// ModelFit: one model (with its enabled effects) identified on a whole recorded run, with what
// the residual loop reports about it: parameters with standard deviations (DYCARO's weighted
// estimate), and per equation group the residual RMS and relative residual norm, in sample and
// held out (cross_validation.hpp), the residual time series and its spectrum.
//
// Rows are those of the streamed server path: the model's rows on each preprocessed segment
// (ingest/recorded_run.hpp), kept on the decimation grid (odmf). The effect may be a model
// effect, a dictionary effect (model/effects.hpp) or a road profile (road_profile.hpp).
//
// Held-out figures: for each fold, the model is fitted on the other folds and the fold's rows
// are predicted; RMS over all predicted rows. "Weighted" figures divide each group's residual by
// the group's sigma from the in-sample fit (DYCARO's 1/sigma_j), so that groups in different
// units add up; with one group the weighted RMS is the RMS in units of that sigma.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/ls/equation_groups.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/cross_validation.hpp"
#include "dynid/residual/spectrum.hpp"

namespace dynid::residual {

struct GroupFit {
  std::string group;
  std::uint64_t rows = 0;
  double sigma = 0.0;                   ///< in-sample residual std of the group (own units)
  double rms_in_sample = 0.0;           ///< unweighted, the group's units
  double relative_norm_in_sample = 0.0; ///< ||r|| / ||y||
  double rms_held_out = 0.0;
  double relative_norm_held_out = 0.0;
};

/// The residual of one group at the in-sample solution, row by row.
struct ResidualSeries {
  std::string group;
  std::vector<double> time_s;   ///< run time of each row (run grid index / sample rate)
  std::vector<Eigen::Index> grid_index;  ///< the run grid index of each row
  Eigen::VectorXd measured;     ///< y
  Eigen::VectorXd residual;     ///< y - W x
  /// The fitted contribution of the last effect's columns (W_effect x_effect); empty without
  /// one. A road profile's is centred on its mean (its level is the offset's: road_profile.hpp).
  Eigen::VectorXd effect_contribution;
  Spectrum spectrum;  ///< of the residual on the decimated grid (gaps between rows read 0)
};

struct ModelFit {
  std::string model;
  std::vector<std::string> effects;  ///< as enabled, the added one last
  std::vector<model::ParameterInfo> parameters;
  ls::Estimate estimate;  ///< DYCARO's weighted estimate (values, std in the parameters' units)
  Eigen::VectorXd column_norms;  ///< of its weighted system, for model::classify_parameters
  std::vector<ls::GroupStatistics> group_statistics;  ///< sigma_j and weights
  std::vector<GroupFit> groups;
  std::vector<ResidualSeries> series;
  double weighted_rms_in_sample = 0.0;
  double weighted_rms_held_out = 0.0;
  /// Road profile fits only: the knot distances (m), in the order of the profile's parameters.
  std::vector<double> profile_knots_m;
};

struct FitOptions {
  CrossValidation cross_validation;
  double profile_knot_spacing_m = 100.0;  ///< for a road-profile effect
  bool series = true;                      ///< fill series (time series and spectra)
  /// Weights of the weighted figures, per group in the model's group order; empty: the fit's
  /// own 1/sigma_j. Give the declared model's weights to compare two fits on one scale.
  std::vector<double> group_weights;
  /// The folds' arithmetic (ls/accumulator.hpp): extended for the published fits; double where
  /// the data are far noisier than double rounding and only noise is measured (the noise floor's
  /// draws).
  ls::Precision precision = ls::Precision::kExtended;
};

/// Fits `model` with `effects` (model, dictionary or road-profile effects; at most one road
/// profile) on the run. InputError when the model lacks a channel, an effect is unknown, no
/// row is left, or group_weights has not one weight per group.
ModelFit fit_model(const model::Model& model, const std::vector<std::string>& effects,
                   const std::vector<ingest::PreprocessedSegment>& run, double sample_rate_hz,
                   int odmf, const FitOptions& options = {});

}  // namespace dynid::residual
