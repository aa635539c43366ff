#pragma once
// Internal helpers shared by the model implementations.
#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include "dynid/model/channel_set.hpp"
#include "dynid/model/constants.hpp"
#include "dynid/model/row_model.hpp"

namespace dynid::model::detail {

/// Standard gravity (m/s^2), the default of the optional constant "gravity".
inline constexpr double kStandardGravity = 9.80665;

inline double sgn(double x) { return static_cast<double>((x > 0.0) - (x < 0.0)); }
/// |x| x: a quadratic law that keeps the sign (nonlinear damping, drag at negative speed).
inline double signed_square(double x) { return std::abs(x) * x; }

/// The channel if present, else nullptr (optional channels).
inline const Eigen::VectorXd* find(const ChannelSet& set, const std::string& name) {
  return set.has(name) ? &set[name] : nullptr;
}

/// A column value at sample k, bound to the channels of one rows() call.
using ValueFn = std::function<double(Eigen::Index k)>;

/// An effect with one parameter whose column is value(k) in group `group` and zero elsewhere.
RowModel::EffectDefinition one_column(Effect info, std::function<ValueFn(const ChannelSet&)> bind,
                                      std::size_t group = 0);

/// One parameter description (a-priori value optional), no bounds: offsets, gains of either
/// sign, terms whose sign physics does not fix.
inline ParameterInfo parameter(std::string name, std::string unit, std::string description,
                               std::optional<double> a_priori = std::nullopt) {
  return {std::move(name), std::move(unit), std::move(description), a_priori};
}

// Physical bounds (ParameterInfo: impossibilities, not priors), put on a parameter():
// positive(parameter("mass", "kg", "vehicle mass")).

/// > 0: masses, inertias, stiffnesses, a sensor scale.
inline ParameterInfo positive(ParameterInfo p) {
  p.lower = 0.0;
  return p;
}

/// >= 0: dissipative terms that may be absent (damping, dry friction, a brake gain).
inline ParameterInfo non_negative(ParameterInfo p) {
  p.lower = 0.0;
  p.lower_inclusive = true;
  return p;
}

/// Excitation facts (ParameterInfo::typical, excited_by; model/parameter_status.hpp):
/// excited(positive(parameter("mass", ...)), 1500.0, "d_vx (accelerate, brake)").
inline ParameterInfo excited(ParameterInfo p, std::optional<double> typical, std::string by) {
  p.typical = typical;
  p.excited_by = std::move(by);
  return p;
}

/// The shared physical quantity the parameter measures (ParameterInfo::quantity):
/// measures(positive(parameter("mass", ...)), "mass").
inline ParameterInfo measures(ParameterInfo p, std::string quantity) {
  p.quantity = std::move(quantity);
  return p;
}

/// <= 0: a term that can only take away (a tyre's saturation).
inline ParameterInfo non_positive(ParameterInfo p) {
  p.upper = 0.0;
  return p;
}

/// In (lower, upper]: a friction coefficient (0, 2], a car's drag area (0, 2] m^2.
inline ParameterInfo bounded(ParameterInfo p, double lower, double upper) {
  p.lower = lower;
  p.upper = upper;
  return p;
}

/// A car's drag area S Cx (m^2): > 0, and <= 2 m^2 (a large van is ~1.2 m^2; Cx ~0.3..0.4
/// over a frontal area of 2..3.5 m^2).
inline ParameterInfo drag_area(std::string description) {
  return bounded(parameter("SCx", "m^2", std::move(description)), 0.0, 2.0);
}

/// The same quantity per unit of an unknown mass M (the lateral models without `mass`: their
/// equations are homogeneous in M): name _per_mass, unit /kg. Dividing by M > 0 keeps a sign
/// bound (0) and loses any other; a typical value is scaled by a passenger car's 1500 kg.
inline ParameterInfo per_unit_mass(ParameterInfo p) {
  p.name += "_per_mass";
  p.unit += "/kg";
  p.description += ", per unit mass";
  if (p.lower && *p.lower != 0.0) p.lower.reset();
  if (p.upper && *p.upper != 0.0) p.upper.reset();
  if (p.typical) *p.typical /= 1500.0;
  return p;
}

}  // namespace dynid::model::detail

namespace dynid::model::detail {

/// A predicate "braking at k" (brake_pressure > threshold); always false when the channel is
/// absent or `allowed` (brake drag modelled).
std::function<bool(Eigen::Index)> braking(const ChannelSet& set, double threshold, bool allowed);

/// The value of a channel at k (bound once).
ValueFn channel(const ChannelSet& set, const std::string& name);

/// The samples within `margin` of a sample where `flagged(k)` holds, over `samples` samples: the
/// rows a low-passed transient reaches (the filter spreads it over its impulse response).
std::vector<bool> within_margin_of(Eigen::Index samples, Eigen::Index margin,
                                   const std::function<bool(Eigen::Index)>& flagged);

/// A margin in seconds as whole samples at `sample_period` (rounded up).
Eigen::Index margin_samples(double margin_s, double sample_period);

/// An optional margin `name` in seconds, 0 when absent; InputError naming it when negative.
double optional_margin(const ConstantReader& c, const std::string& name);

/// The optional constant brake_pressure_threshold (Pa, 2e4 = 0.2 bar): above it a row counts as
/// braking, for every model that leaves braking rows out.
double brake_pressure_threshold(const ConstantReader& c);

/// Per sample: braking (braking(set, threshold, allowed)) or within `margin_s` of it. Why the
/// margin: the low-pass spreads the brake force's step over its impulse response, into rows
/// whose own filtered pressure is below the threshold.
std::vector<bool> near_braking(const ChannelSet& set, double threshold, double margin_s,
                               bool allowed);

/// `r` widened to read `margin_s` on both sides of a row: a model whose mask looks that far
/// (near_stick, braking) says so, so that a streaming caller keeps that much context.
RowReach widened(RowReach r, double margin_s, double sample_period);

/// A predicate "the clutch sticks at k": |engine_speed - gearbox_input_speed| < min_slip, where
/// the slip's sign, and so the friction's, is undefined.
std::function<bool(Eigen::Index)> clutch_sticks(const ChannelSet& set, double min_slip);

/// The clutch models' ECU torque offset T0 (true = ECU + T0): a column -1 on the engine side.
RowModel::EffectDefinition clutch_torque_offset();

/// The brake-drag effect: a force or torque k_b p proportional to brake pressure, on the
/// resisting side; `parameter_name`, `unit` of k_b.
RowModel::EffectDefinition brake_drag(const std::string& parameter_name, const std::string& unit);

}  // namespace dynid::model::detail

namespace dynid::model::detail {

/// The corner on the other side of the same axle (fl <-> fr, rl <-> rr); InputError naming
/// `model` for anything but fl, fr, rl, rr.
std::string opposite_corner(const std::string& corner, const std::string& model);

}  // namespace dynid::model::detail
