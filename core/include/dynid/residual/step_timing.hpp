#pragma once
// StepTiming: the sampling error of a signal that steps between two samples, for the noise
// floor's draws (noise_floor.hpp, 2.).
//
// Why: a sampled signal says that a step happened between two samples, not when. An engine's
// torque steps when the pedal steps, a clutch's when it locks; the message samples it every
// period, the resampler interpolates between frames (a ramp across the frame interval), and the
// low-pass then puts the step at the ramp's middle. The true time is anywhere in the interval,
// uniform, so the filtered channel differs from the filtered truth by an impulse of area
// size x (t_true - t_middle), up to half a frame period. A signal that is continuous across the
// same moment (the speed, the integral of the force) keeps its timing, so an exact model's
// residual holds a burst at every step of a channel it reads: on the independent car's clean
// acceleration run with every sensor's noise off, the wheel-torque model left 282 N^2 of
// residual mean square, and these draws predict 153 N^2 (most of the rest is in ramps too fast
// for the samples to resolve fully, a clutch actuator's 30 ms, which are not counted: below).
// The noise measurement cannot see it (its median ignores the windows that hold a step, which
// are rightly not noise), so without this share the floor is low wherever torques step.
//
// find_steps: a step is an increment of the grid samples that departs from the local slope (the
// median of the increments 2 to 5 away on either side, which a step spread over up to three
// increments leaves clean; a smooth signal's slope and curvature cancel in it) by more than
// kStepSigmas x sigma sqrt(2) (sigma: the channel's white noise at the grid rate; a false step,
// at 1 in 10^6 increments of Gaussian noise, adds a share of its own size, which is noise).
// Consecutive departures are one departure spread over several grid intervals; its
// parts are the increments above the slope outside them, its size their sum, its span in grid
// intervals sum |part| / max |part|. A step is spread by the interpolation over one frame
// interval, whatever its size, while a fast ramp that the samples resolve (a clutch engaging, a
// torque ramped over 50 ms) spreads over more and its time is in the samples: the channel's
// frame interval is taken as its sharpest departure's span (exact where the frame interval
// covers a whole grid interval, a slower message; up to twice it for a message at the grid rate,
// conservative), and only departures within it plus one grid interval of phase are steps, each
// given that span. Measured on the project's own simulator, whose wheel torque ramps: counted
// as steps of their own spans, its ramps of 3-5 grid intervals raised a brake-drag run's floor
// mean square by 56 % and hid the pitch dynamics left beside the brake drag. Only increments
// whose samples and those five beyond either side are valid are looked at.
//
// add_step_timing: one draw of the timing error, each step's impulse of area
// size x span x u grid samples (u uniform in [-1/2, 1/2], independent per step) put on the two
// samples around its centre.
#include <Eigen/Dense>
#include <cstdint>
#include <random>
#include <vector>

namespace dynid::residual {

struct SampledStep {
  double centre = 0.0;  ///< in grid samples from the first of the vector (between two samples)
  double size = 0.0;    ///< the step, in the channel's unit
  double span = 1.0;    ///< the channel's frame interval, in grid intervals (>= 1)
};

/// Departures beyond this many std of an increment's noise are steps (above).
inline constexpr double kStepSigmas = 5.0;

/// The steps of `x` (grid samples; `valid` one flag per sample) beyond its noise `sigma` (> 0).
std::vector<SampledStep> find_steps(const Eigen::VectorXd& x,
                                    const std::vector<std::uint8_t>& valid, double sigma);

/// Adds one draw of the steps' timing error to `x` (above).
void add_step_timing(const std::vector<SampledStep>& steps, std::mt19937_64& rng,
                     Eigen::VectorXd& x);

}  // namespace dynid::residual
