#pragma once
// Varying parameters: candidate effects for a parameter that is not constant over the run
// (issue 15: "a load change at a stop, a friction level that drifts over the run"). Each is one
// extra column made of a declared parameter's own column W_j:
//   drift:<parameter>          W_j (t - t_mid)      the parameter changes linearly with time;
//                                                    its coefficient is the rate (unit / s), the
//                                                    parameter itself its value at mid-run
//   step:<parameter>@<t0>s     W_j [t >= t0]        the parameter changes at t0 (s of run time);
//                                                    its coefficient is the change
//   drift:<parameter>~<q>      W_j (Q - Q_mean)     the parameter changes with a quantity Q that
//                                                    accumulates over the run: "distance" (the
//                                                    integral of |vx|, m; tyres wearing or
//                                                    warming with the kilometres) or
//                                                    "clutch_energy" (of |engine_torque x slip
//                                                    speed|, J; a facing fading with the heat it
//                                                    took); its coefficient is the change per
//                                                    unit of Q
//   depends:<parameter>~<ch>   W_j (x - x_mean)     the parameter depends on channel x (a
//                                                    cornering stiffness on the load, an offset
//                                                    on the engine speed: "a model column times a
//                                                    channel"); its coefficient is the change per
//                                                    unit of x, the parameter its value at x's
//                                                    run mean
// Q is integrated over the run's valid samples from its start (a gap between segments adds
// nothing: its motion was not measured); the quantities are named by the channel catalogue, so
// any car whose profile maps those channels has them.
// The residual screen offers a drift of every parameter of the model (with time and with every
// cumulative quantity the run's channels allow), a step at every
// cross-validation block boundary but the first and the last (a step needs data on both sides;
// on a run of more than kMaxStepTimes such boundaries, at every k-th, k the smallest that keeps
// at most that many: see varying_candidates), and a dependence of every parameter on every channel
// of the model's physics that is not on its measured side; a step found is reported as a time. The
// column enters every equation group where W_j does. On a run at nearly constant speed a drift or
// step of an offset and a road profile (a function of distance) explain the same residual: the
// screen prefers the profile within one standard error (effect_screen.hpp).
#include <optional>
#include <string>
#include <vector>

#include "dynid/model/model.hpp"

namespace dynid::residual {

struct VaryingParameter {
  enum class Kind { kDrift, kStep, kChannel, kCumulative } kind = Kind::kDrift;
  std::string parameter;
  Eigen::Index column = 0;  ///< the parameter's column in the model's rows
  double step_time_s = 0.0; ///< kStep: t0
  std::string channel;      ///< kChannel: x; kCumulative: the quantity Q
};

/// The cumulative quantities whose every channel is among `channels` (see above), in a fixed
/// order. The screen passes the model's physics channels that the run has: a parameter drifting
/// with a quantity its model does not read (the clutch's energy for a cornering stiffness) is
/// no physics, and on a run where that quantity is noise (slip speed with the clutch closed) it
/// accumulates as time does.
std::vector<std::string> cumulative_quantities(const std::vector<std::string>& channels);
/// The rate of `quantity` at every sample of `channels` (per second; 0 where a sample is invalid
/// or not finite). InputError naming the quantity when it is unknown or a channel it reads is
/// missing.
Eigen::VectorXd cumulative_rate(const std::string& quantity, const model::ChannelSet& channels);

bool is_varying_effect(const std::string& name);

/// Parses `name` against `model`'s parameters. InputError naming the effect when the form is
/// wrong, the parameter unknown, t0 not a finite number, the channel name empty or the
/// quantity unknown.
VaryingParameter parse_varying_effect(const std::string& name, const model::Model& model);

/// The parameter the effect adds (no physical bounds: a change may have either sign).
model::ParameterInfo varying_parameter_info(const VaryingParameter& v, const model::Model& model);

/// The step times tried per parameter at most. Why a bound: each step time is a fit of the
/// whole run, so with one per block the screen's cost grew with the square of the run's length
/// (a 10-minute run: 118 per parameter), while a coarser grid loses little of a step's test: the
/// tested time nearest a step at t* differs from it on at most half a spacing of rows (1/64 of
/// the run), and the step's non-centrality keeps the squared correlation of the two step
/// columns, t*(T - t) / (t (T - t*)) for a tested t after t* (a step mid-run: 31/33, 6 % lost),
/// while the level gained by testing fewer times is larger (Bonferroni over the candidates: on an
/// hour's run of the three-parameter lateral model about 200 candidates instead of 2250, and the
/// non-centrality a test needs for 80 % power, (z + 0.84)^2, about a fifth lower). The step found
/// is then located on the rows themselves (change_point.hpp), at every row, whatever the grid.
constexpr int kMaxStepTimes = 32;

/// The names the screen tries on a run spanning [t_first, t_last] s with blocks of `block_s`,
/// a dependence on each of `channels`, a drift with each of `quantities`.
std::vector<std::string> varying_candidates(const model::Model& model, double t_first, double t_last,
                                            double block_s, const std::vector<std::string>& channels = {},
                                            const std::vector<std::string>& quantities = {});

/// The column's value on a row of W_j = `w`, at run time t, for a run whose middle is t_mid;
/// `centred` is x - x_mean of a kChannel's channel, or Q - Q_mean of a kCumulative's quantity, at
/// that row (ignored otherwise).
double varying_column(const VaryingParameter& v, double w, double t, double t_mid, double centred = 0.0);

}  // namespace dynid::residual
