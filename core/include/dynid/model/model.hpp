#pragma once
// Model: one identification model, linear in its parameters (Venture 2003 §2.B: Y = W X + rho).
//
// A model declares its parameters (name, SI unit, a-priori value), the channels it needs, its
// equation groups (one accumulator each, weighted by DYCARO's 1/sigma_j) and its candidate
// effects: named extra columns that the residual loop may add. Given preprocessed channels it
// builds the regressor rows of every group. Models hold only constants (from the vehicle
// profile): they are immutable and may be shared by threads.
//
// Column order of the rows: parameters() first, then, for each enabled effect in the order
// given, that effect's parameters. Rows at invalid samples (ChannelSet::valid) and samples the
// model must mask (e.g. a clutch model where the slip speed is ~0, a longitudinal model while
// braking when brake force is not modelled) are left out.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/channel_set.hpp"

namespace dynid::model {

/// One parameter of a model or of an effect.
///
/// Bounds: what physics allows at all, not a prior. A value outside them is impossible for the
/// quantity the parameter names (a negative mass, a drag area of 5 m^2 on a car, a negative
/// damper): an estimate there says the data or the model is wrong, never that the car is
/// unusual. So bounds are wide ("> 0", "(0, 2]") and absent where the sign is not fixed by
/// physics (offsets, gains of either sign, dictionary terms, road-profile knots).
/// lower_inclusive / upper_inclusive say whether the bound itself is allowed; the defaults are
/// the common case, a strict lower bound and an inclusive upper one: mass > 0, an efficiency in
/// (0, 1]; damping >= 0 sets lower_inclusive. Per-unit-mass variants (lateral_bicycle without
/// a mass) keep the sign bounds only. The bounds are of the parameter as named, in its unit.
struct ParameterInfo {
  std::string name;         ///< e.g. "mass", unique within the model and its effects
  std::string unit;         ///< SI, e.g. "kg", "N/rad", "kg m^2"
  std::string description;
  std::optional<double> a_priori;  ///< a known or nominal value, if any
  std::optional<double> lower = std::nullopt;  ///< physical lower bound, if any
  std::optional<double> upper = std::nullopt;  ///< physical upper bound, if any
  bool lower_inclusive = false;  ///< value == lower allowed (">= 0"); default strict ("> 0")
  bool upper_inclusive = true;   ///< value == upper allowed ("<= 2"); default inclusive
  /// Excitation (dynid/model/parameter_status.hpp): the order of magnitude the quantity has on
  /// a passenger car (1500 kg, 0.2 kg m^2), only to judge whether a run carries information
  /// about it; never a prior, never in the fit. Absent where no magnitude is typical.
  std::optional<double> typical = std::nullopt;
  /// The signal that must move for the column to carry information, named by its channel and
  /// the manoeuvre that moves it: "d_vx (accelerate, brake)". Printed for a parameter the run
  /// does not excite.
  std::string excited_by = {};
  /// The physical quantity of the car the parameter measures, named alike by every model that
  /// measures the same one ("mass", "ax_sensor_scale", "engine_inertia" of the engine side of the
  /// clutch); residual/consistency.hpp compares only parameters of one quantity, and a reference
  /// value given for it applies to them alone. Empty: a coefficient of this model only (a
  /// sensor scale of an axis no other model reads, an inertia that includes another body's).
  std::string quantity = {};

  /// The name a consistency reference value is given under: the quantity when declared, else
  /// the parameter's name.
  const std::string& reference_key() const { return quantity.empty() ? name : quantity; }
  /// True when `value` is within the bounds, and for NaN: a parameter that is not identifiable
  /// (NaN estimate) is not out of bounds. +-Inf is out of any bound on its side.
  bool within_bounds(double value) const;
  /// The bounds in one line for reports: "> 0", ">= 0", "<= 0", "(0, 2]"; "" when none.
  std::string bounds_text() const;
};

struct ChannelNeed {
  std::string name;  ///< from docs/CHANNELS.md
  std::string unit;
  bool optional = false;  ///< used when present (e.g. by an effect), not required
};

struct Effect {
  std::string name;         ///< e.g. "road_grade", "anti_roll_bar", "dict:sq:vx"
  std::string description;  ///< the physics, one line
  std::vector<ParameterInfo> parameters;  ///< the extra columns it adds
  std::vector<std::string> channels;      ///< channels it needs beyond the model's own
  /// The manoeuvre that tells this effect apart from the model's parameters, where the physics
  /// says so (residual/separability.hpp); empty: none stated.
  std::string separated_by = "";
};

/// How far from its own sample a row reads, in samples: the row at k depends on samples
/// [k - back, k + ahead] only. A streaming caller (ingest::RunProcessor) gives every row at
/// least that much context and look-ahead, so that each row is the one of a whole-record call.
struct RowReach {
  Eigen::Index back = 3;   ///< the dictionary's lags (lag1..lag3)
  Eigen::Index ahead = 1;  ///< central differences, neighbour tests
};

struct GroupRows {
  std::string group;
  Eigen::MatrixXd W;  ///< rows x (parameters + enabled effects' parameters)
  Eigen::VectorXd y;
  std::vector<Eigen::Index> samples;  ///< the sample index of each row (for residual plots)
};

class Model {
 public:
  virtual ~Model() = default;

  virtual std::string name() const = 0;
  virtual std::vector<ParameterInfo> parameters() const = 0;
  virtual std::vector<ChannelNeed> channels() const = 0;
  virtual std::vector<std::string> groups() const = 0;
  /// The SI unit of group `group`'s measured side y, and so of its fitted values and residual
  /// ("N", "N m", "m/s^2"): what an export or a plot labels them with. `group` is one of groups().
  virtual std::string group_unit(const std::string& group) const = 0;
  /// The model's physical candidate effects (the generic dictionary is added by
  /// dictionary_effects(), see effects.hpp).
  virtual std::vector<Effect> candidate_effects() const = 0;

  /// Rows of every group. Throws InputError naming a missing channel or an unknown effect, and
  /// for channels that cannot give a sound estimate (constant where excitation is needed, ...).
  virtual std::vector<GroupRows> rows(const ChannelSet& channels,
                                      const std::vector<std::string>& effects = {}) const = 0;
  /// Rows of every group at the chosen samples only: `samples` are sample indices of
  /// `channels`, strictly increasing. Each row is exactly (bit for bit) the row rows() builds at
  /// that sample, since a row still reads its neighbours (lags, validity of adjacent samples)
  /// from the whole `channels`; a chosen sample that is invalid or masked gives no row. For a
  /// caller that keeps only some samples (the decimation grid) and would discard the rest.
  /// Throws InputError as rows() does, and for a selection out of range or not increasing.
  virtual std::vector<GroupRows> rows_at(const ChannelSet& channels,
                                         const std::vector<Eigen::Index>& samples,
                                         const std::vector<std::string>& effects = {}) const = 0;

  /// The reach of a row at this sample period (s), with every effect: the default covers the
  /// dictionary and one-sample neighbour tests; a model that reads further (a masking rule
  /// over a time window) says so here, or a streaming caller builds its rows on a window too
  /// short to see what the rule needs and masks by luck of the chunk boundaries.
  virtual RowReach reach(double sample_period) const;

  /// Parameters that are constants of one run, not of the car (a sensor offset drawn again at
  /// each power-up): pooled estimates eliminate them run by run before merging
  /// (ingest/run_nuisance.hpp). Default: none.
  virtual std::vector<std::string> per_run_parameters() const { return {}; }

  /// The channels the measured side y is made of (e.g. the torque or force sensor). The
  /// residual loop offers no dictionary effect over them: a column made of y itself (or of its
  /// lag) "explains" any residual without meaning anything. Default: none.
  virtual std::vector<std::string> measured_side() const { return {}; }

  /// All parameters with the enabled effects' parameters appended, in column order.
  std::vector<ParameterInfo> parameters_with(const std::vector<std::string>& effects) const;
  /// True when every non-optional channel is present.
  bool can_run_on(const ChannelSet& channels) const;
};

}  // namespace dynid::model
