#pragma once
// Candidate effects: named extra columns the residual loop may add to a model (DESIGN.md
// "Models"; the "missing effect" stories of venture §7 and borsotto §5).
//
// Physical effects are declared by each model (Model::candidate_effects()), under the shared
// names below so that the residual loop and the reports speak one vocabulary. The generic
// dictionary covers effects nobody listed: for every channel x present in a ChannelSet,
//     dict:x:<x>     x                  dict:sgn:<x>   sgn x
//     dict:sq:<x>    x^2                dict:d:<x>     dx/dt (central difference)
//     dict:absx:<x>  |x| x              dict:lag<L>:<x> x delayed by L = 1, 2, 3 samples
//     dict:prod:<a>*<b>  a b: an interaction of two channels (every pair of the set, a before b
//                        in the set's order), e.g. a torque error that grows with engine speed
//                        times the gear, a stiffness that changes with the lateral acceleration
// Every model accepts these names. A dictionary effect adds one parameter per equation group
// (an unknown effect enters each equation with its own coefficient): named `<effect>` when the
// model has one group, `<effect>@<group>` otherwise; its column is zero in the other groups.
// Rows whose derivative or lag would reach outside the run or into an invalid sample are left
// out.
#include <string>
#include <vector>

#include "dynid/model/channel_set.hpp"
#include "dynid/model/model.hpp"

namespace dynid::model {

namespace effect {
inline constexpr const char* kRoadGrade = "road_grade";  ///< g sin(grade) from `road_grade`
/// Grade seen by the accelerometer against the wheel-speed derivative: ax - d_vx = g sin(grade).
inline constexpr const char* kRoadGradeAccelerometer = "road_grade_accelerometer";
inline constexpr const char* kRoadBank = "road_bank";
inline constexpr const char* kAeroDrag = "aero_drag";
inline constexpr const char* kLinearDrag = "linear_drag";  ///< speed-proportional rolling loss
inline constexpr const char* kBrakeDrag = "brake_drag";    ///< force proportional to pressure
inline constexpr const char* kRotatingInertia = "rotating_inertia";
inline constexpr const char* kAntiRollBar = "anti_roll_bar";
inline constexpr const char* kNonlinearDamping = "nonlinear_damping";  ///< |v| v
inline constexpr const char* kProgressiveStiffness = "progressive_stiffness";  ///< x^3 or x^2
inline constexpr const char* kTyreDamping = "tyre_damping";
inline constexpr const char* kTyreSaturation = "tyre_saturation";  ///< |alpha| alpha (Fiala)
inline constexpr const char* kStribeck = "stribeck_friction";
inline constexpr const char* kViscous = "viscous_friction";
inline constexpr const char* kTorqueOffset = "engine_torque_offset";  ///< sensor offset
inline constexpr const char* kSteerOffset = "steer_offset";          ///< sensor offset
/// Constant slip-angle offsets on both axles (steer, vy and yaw-rate sensor offsets).
inline constexpr const char* kSlipOffset = "slip_offset";
/// Body roll acceleration in the lateral and yaw rows (masses not rolling, J_xz).
inline constexpr const char* kRollAcceleration = "roll_acceleration";
/// A body-fixed accelerometer rolls with the body: it reads g sin(roll) more than the road-plane
/// lateral acceleration (`roll`: body roll to the road).
inline constexpr const char* kRollGravity = "roll_gravity";
inline constexpr const char* kForceOffset = "hub_force_offset";      ///< sensor offsets
inline constexpr const char* kDictionaryPrefix = "dict:";
}  // namespace effect

/// The dictionary effects over the channels present in `channels` (one parameter each, named
/// like the effect; see above for how a model with several groups expands them).
std::vector<Effect> dictionary_effects(const ChannelSet& channels);

/// True when `name` has the form dict:<op>:<channel> with a known op (the channel is not
/// checked here: rows() checks it against the data).
bool is_dictionary_effect(const std::string& name);

/// The effect `name` as a model with `groups` sees it (one parameter per group). Throws
/// InputError naming the effect when it is not a dictionary name.
Effect dictionary_effect(const std::string& name, const std::vector<std::string>& groups);

}  // namespace dynid::model
