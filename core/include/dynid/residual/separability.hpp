#pragma once
// Separability: the physical effects a run cannot tell apart from the declared parameters
// (issue 15: "a candidate nearly collinear with the declared columns on this run (a head wind
// against SCx and rolling resistance) is reported as 'cannot be separated on this run', with the
// parameters it would bias and by how much, and the manoeuvre that would separate it").
//
// The argument is a power calculation, not a collinearity threshold. For each physical
// candidate effect of one column that the diagnosis did not accept (effect_screen.hpp),
// the screen states the smallest coefficient its test would have found with 80 % power
// (`detectable`) and how far each declared parameter moves per unit of that coefficient when the
// effect is left out (`alias`, the omitted-variable identity). An effect of the detectable size
// can therefore be in the data unseen; it is reported when it would move some declared
// parameter by more than kShiftInStd of that parameter's standard deviations, i.e. when the
// parameter's stated uncertainty does not cover what the run cannot rule out. A candidate whose
// column is a combination of the declared ones on this run (not testable) is reported as not
// identifiable at all. A candidate that is significant but not accepted (the residual is at
// the floor: a structure smaller than the noise) is judged by its fitted coefficient instead: a
// head wind's linear term, significant at the floor, that would move SCx by 50 of its std.
//
// The manoeuvre that would separate it: the effect's own model::Effect::separated_by when the
// model states one (a head wind and tyre losses: coast-downs in both directions of one road),
// otherwise a run in which the effect's column varies apart from the parameter's.
#include <string>
#include <vector>

#include "dynid/model/model.hpp"
#include "dynid/residual/effect_screen.hpp"

namespace dynid::residual {

/// A shift beyond this many of the parameter's standard deviations is reported.
inline constexpr double kShiftInStd = 2.0;

struct Inseparable {
  std::string effect;
  std::string description;
  bool identifiable = true;  ///< false: its column is a combination of the declared ones here
  bool significant = false;  ///< the screen found it, the diagnosis did not accept it
  double detectable = 0.0;   ///< the smallest coefficient the screen would find (80 % power);
                             ///< for a significant one, its fitted coefficient
  std::string unit;          ///< of detectable
  std::string parameter;     ///< the declared parameter it would move most, in its std
  double shift = 0.0;        ///< that parameter's move at `detectable`, in its unit
  double shift_relative = 0.0;  ///< shift / |value|
  double shift_in_std = 0.0;    ///< shift / its standard deviation
  std::string separated_by;     ///< the manoeuvre that would separate it
  /// One sentence for the engineer.
  std::string statement() const;
};

/// The physical candidates of `screen` but `accepted` that this run cannot separate (see
/// above), the largest shift (in std) first.
std::vector<Inseparable> inseparable_effects(const model::Model& model, const ScreenResult& screen,
                                             const std::string& accepted = "");

}  // namespace dynid::residual
