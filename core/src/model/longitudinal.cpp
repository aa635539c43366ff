#include "dynid/model/longitudinal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::non_negative;
using detail::excited;
using detail::parameter;
using detail::positive;

LongitudinalModel::LongitudinalModel(const Constants& constants, Source source) : source_(source) {
  const ConstantReader c(constants, name());
  wheel_radius_ = c.positive("wheel_radius", "m, rolling radius of the driven wheels");
  air_density_ = c.positive("air_density", "kg/m^3");
  if (source_ == Source::kEngineTorque) {
    efficiency_ = c.positive("driveline_efficiency", "engine to wheel, 0 < eta <= 1");
    if (efficiency_ > 1.0)
      throw InputError("model '" + name() + "': constant 'driveline_efficiency' > 1");
  }
  gravity_ = c.positive_or("gravity", detail::kStandardGravity);
  min_speed_ = c.positive_or("min_speed", 1.0);
  brake_threshold_ = detail::brake_pressure_threshold(c);
  slip_tolerance_ = c.positive_or("clutch_slip_tolerance", 1.0);
  slip_margin_ = detail::optional_margin(c, "clutch_slip_margin");
  brake_margin_ = detail::optional_margin(c, "brake_margin");
  wheel_torque_zero_ = c.optional("wheel_torque_zero").value_or(0.0);
  if (source_ == Source::kEngineTorque) read_gear_ratios(c);
}

void LongitudinalModel::read_gear_ratios(const ConstantReader& c) {
  // Every name is asked for, so that `dynid models` and a profile's unread-constant check know
  // them all.
  std::vector<std::optional<double>> listed;
  for (int gear = 1; gear <= kMaxGears; ++gear)
    listed.push_back(c.optional("gear_ratio_" + std::to_string(gear)));
  gear_ratio_tolerance_ = c.positive_or("gear_ratio_tolerance", 0.03);
  for (int gear = 1; gear <= kMaxGears; ++gear) {
    const std::string key = "gear_ratio_" + std::to_string(gear);
    if (!listed[static_cast<std::size_t>(gear - 1)]) {
      for (int later = gear + 1; later <= kMaxGears; ++later)
        if (listed[static_cast<std::size_t>(later - 1)])
          throw InputError("model '" + name() + "': constant 'gear_ratio_" + std::to_string(later) +
                           "' is given without '" + key +
                           "' (the gears are numbered from 1 without a hole)");
      break;
    }
    gear_ratios_.push_back(
        c.positive(key, "engine-to-wheel ratio in forward gear " + std::to_string(gear)));
  }
  std::sort(gear_ratios_.begin(), gear_ratios_.end());
  for (std::size_t i = 1; i < gear_ratios_.size(); ++i)
    if (gear_ratios_[i] <= gear_ratios_[i - 1] * std::pow(1.0 + gear_ratio_tolerance_, 2))
      throw InputError(
          "model '" + name() + "': gear ratios " + std::to_string(gear_ratios_[i - 1]) + " and " +
          std::to_string(gear_ratios_[i]) + " are within twice gear_ratio_tolerance (" +
          std::to_string(gear_ratio_tolerance_) + ") of each other: a measured ratio between " +
          "them could be either gear");
}

std::string LongitudinalModel::name() const {
  return source_ == Source::kEngineTorque ? "longitudinal_engine" : "longitudinal_wheel";
}

std::vector<std::string> LongitudinalModel::measured_side() const {
  return {source_ == Source::kWheelTorque ? "wheel_torque" : "engine_torque"};
}

std::vector<ParameterInfo> LongitudinalModel::parameters() const {
  // F_r >= 0: rolling resistance only takes energy (a negative one says that a torque offset,
  // the same column within a gear, is left in the data).
  // Typical magnitudes of a passenger car, for judging excitation only: at constant speed
  // the drag and rolling-resistance columns are proportional (v^2 and 1).
  // Both sources measure the same car: the quantities are shared (consistency.hpp).
  return {
      excited(
          detail::measures(positive(parameter("mass", "kg", "vehicle mass (translating)")), "mass"),
          1500.0, "d_vx (accelerate, brake)"),
      excited(detail::measures(detail::drag_area("aerodynamic drag area S Cx"), "SCx"), 0.7,
              "vx over a wide range (coast down from high speed)"),
      excited(detail::measures(non_negative(parameter("rolling_resistance", "N",
                                                      "rolling resistance force F_r = C_rr M g")),
                               "rolling_resistance"),
              200.0, "vx over a wide range (coast down from high speed)")};
}

std::vector<ChannelNeed> LongitudinalModel::channels() const {
  std::vector<ChannelNeed> out{{"vx", "m/s"}, {"d_vx", "m/s^2"}};
  if (source_ == Source::kEngineTorque) {
    out.push_back({"engine_torque", "N m"});
    // With the gears' ratios listed the ratio is inferred from the engine speed (header).
    if (gear_ratios_.empty()) out.push_back({"gear_ratio", "-"});
    out.push_back({"gear", "-", true});
    out.push_back({"engine_speed", "rad/s", gear_ratios_.empty()});
    out.push_back({"gearbox_input_speed", "rad/s", true});
  } else {
    out.push_back({"wheel_torque", "N m"});
  }
  out.push_back({"brake_pressure", "Pa", true});
  out.push_back({"road_grade", "rad", true});
  out.push_back({"ax", "m/s^2", true});
  return out;
}

std::function<LongitudinalModel::Drive(Eigen::Index)> LongitudinalModel::drive(
    const ChannelSet& set) const {
  const double r = wheel_radius_;
  if (source_ == Source::kWheelTorque) {
    const Eigen::VectorXd& t = set["wheel_torque"];
    return [&t, r, zero = wheel_torque_zero_](Eigen::Index k) { return Drive{(t(k) - zero) / r, 1.0 / r}; };
  }
  const Eigen::VectorXd& t = set["engine_torque"];
  const Eigen::VectorXd* gear = detail::find(set, "gear");
  const double eta = efficiency_;
  return [&t, ratio_at = ratio(set), gear, eta, r](Eigen::Index k) {
    if (gear != nullptr && std::lround((*gear)(k)) == 0) return Drive{0.0, 0.0};
    // Driving, the driveline loses (1 - eta) of the engine's power; dragging, of the wheels'.
    const double factor = (t(k) >= 0.0 ? eta : 1.0 / eta) * ratio_at(k) / r;
    return Drive{t(k) * factor, factor};
  };
}

std::function<double(Eigen::Index)> LongitudinalModel::ratio(const ChannelSet& set) const {
  if (gear_ratios_.empty()) {
    const Eigen::VectorXd& ratio = set["gear_ratio"];
    return [&ratio](Eigen::Index k) { return ratio(k); };
  }
  const Eigen::VectorXd& engine = set["engine_speed"];
  const Eigen::VectorXd& vx = set["vx"];
  return [&engine, &vx, &listed = gear_ratios_, r = wheel_radius_,
          limit = std::log1p(gear_ratio_tolerance_)](Eigen::Index k) {
    const double measured = engine(k) * r / vx(k);
    if (!(measured > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    // The nearest listed ratio in log: the first at or above the measured one, or the one below.
    auto above = std::lower_bound(listed.begin(), listed.end(), measured);
    double nearest = above == listed.end() ? listed.back() : *above;
    if (above != listed.begin() &&
        (above == listed.end() || std::log(measured / *(above - 1)) < std::log(*above / measured)))
      nearest = *(above - 1);
    return std::abs(std::log(measured / nearest)) <= limit
               ? nearest
               : std::numeric_limits<double>::quiet_NaN();
  };
}

std::vector<RowModel::EffectDefinition> LongitudinalModel::effect_definitions() const {
  const double g = gravity_;
  std::vector<EffectDefinition> out{
      detail::one_column(
          {effect::kRoadGrade,
           "grade load M g sin(grade) from the road_grade channel",
           // A mass: > 0 with road_grade positive uphill (docs/CHANNELS.md).
           {excited(positive(parameter("grade_mass", "kg",
                                       "mass seen by the grade (= mass if grade explains it)")),
                    1500.0, "road_grade (a hilly road)")},
           {"road_grade"}},
          [g](const ChannelSet& set) -> detail::ValueFn {
            const Eigen::VectorXd& grade = set["road_grade"];
            return [&grade, g](Eigen::Index k) { return g * std::sin(grade(k)); };
          }),
      detail::one_column(
          {effect::kRoadGradeAccelerometer,
           "grade load M (ax - d_vx): the accelerometer sees g sin(grade), the wheels do not",
           {excited(positive(parameter("grade_mass_accelerometer", "kg", "mass seen by the grade")),
                    1500.0, "ax - d_vx (a hilly road)")},
           {"ax"}},
          [](const ChannelSet& set) -> detail::ValueFn {
            const Eigen::VectorXd& ax = set["ax"];
            const Eigen::VectorXd& dvx = set["d_vx"];
            return [&ax, &dvx](Eigen::Index k) { return ax(k) - dvx(k); };
          }),
      detail::one_column(
          {effect::kLinearDrag,
           "resistance proportional to speed (tyre losses)",
           {detail::measures(
               non_negative(parameter("linear_drag", "N s/m", "speed-proportional resistance")),
               "linear_drag")},
           {},
           // A head wind w adds rho SCx w v (this column) and a constant (rolling resistance's):
           // runs in opposite directions change its sign, tyre losses keep theirs (SAE J2263).
           "coast-downs in both directions of one road, from high speed down (a wind changes sign "
           "with the direction, tyre losses do not)"},
          [](const ChannelSet& set) { return detail::channel(set, "vx"); }),
      detail::brake_drag("brake_force_gain", "N/Pa")};
  if (source_ != Source::kEngineTorque) return out;
  auto factor = [this](const ChannelSet& set) { return drive(set); };
  out.push_back(detail::one_column(
      {effect::kTorqueOffset,
       "engine torque sensor offset T0: F_drive = eta G (T + T0) / r_w",
       {detail::measures(parameter("engine_torque_offset", "N m", "offset of the ECU torque", 0.0),
                         "engine_torque_offset")},
       {}},
      [factor](const ChannelSet& set) -> detail::ValueFn {
        return [d = factor(set)](Eigen::Index k) { return -d(k).factor; };
      }));
  const double r = wheel_radius_;
  out.push_back(detail::one_column(
      {effect::kRotatingInertia,
       "engine inertia through the gear: eta J_e G^2 / r_w^2 d_vx",
       // No shared quantity: with the clutch closed the gearbox input turns with the engine, so
       // this is J_e + J_in, not the clutch model's J_e.
       {positive(parameter("engine_inertia", "kg m^2", "rotating inertia on the engine side"))},
       {}},
      [this, factor, r](const ChannelSet& set) -> detail::ValueFn {
        const Eigen::VectorXd& dvx = set["d_vx"];
        return [d = factor(set), ratio_at = ratio(set), &dvx, r](Eigen::Index k) {
          // In neutral nothing turns the engine through a gear (and an inferred ratio is none).
          const double drive = d(k).factor;
          return drive == 0.0 ? 0.0 : drive * ratio_at(k) / r * dvx(k);
        };
      }));
  return out;
}

RowReach LongitudinalModel::reach(double sample_period) const {
  const RowReach r = detail::widened(Model::reach(sample_period), brake_margin_, sample_period);
  return source_ == Source::kEngineTorque ? detail::widened(r, slip_margin_, sample_period) : r;
}

RowModel::RowFn LongitudinalModel::bind(const ChannelSet& set,
                                        const std::vector<std::string>& effects) const {
  const Eigen::VectorXd& vx = set["vx"];
  const Eigen::VectorXd& dvx = set["d_vx"];
  const Eigen::VectorXd* engine = detail::find(set, "engine_speed");
  const Eigen::VectorXd* input = detail::find(set, "gearbox_input_speed");
  const bool measured_slip =
      source_ == Source::kEngineTorque && engine != nullptr && input != nullptr;
  // With the gear inferred, a row no listed gear fits is a slipping or open clutch too (header),
  // and its neighbours within clutch_slip_margin carry its transient as well.
  // A gear channel's neutral (gear 0) is no slip: the drive is zero there, the row a coast.
  const bool inferred_slip = source_ == Source::kEngineTorque && !gear_ratios_.empty();
  const Eigen::VectorXd* gear = detail::find(set, "gear");
  const bool slip_check = measured_slip || inferred_slip;
  const std::function<double(Eigen::Index)> ratio_at =
      inferred_slip ? ratio(set) : std::function<double(Eigen::Index)>{};
  const std::vector<bool> slipping =
      slip_check ? detail::within_margin_of(
                       set.samples(), detail::margin_samples(slip_margin_, set.sample_period()),
                       [&](Eigen::Index k) {
                         return (measured_slip &&
                                 std::abs((*engine)(k) - (*input)(k)) > slip_tolerance_) ||
                                (inferred_slip && !std::isfinite(ratio_at(k)) &&
                                 !(gear != nullptr && std::lround((*gear)(k)) == 0));
                       })
                 : std::vector<bool>{};
  const std::vector<bool> braking = detail::near_braking(set, brake_threshold_, brake_margin_,
                                                         enabled(effects, effect::kBrakeDrag));
  const double half_rho = 0.5 * air_density_;
  return [=, this, &vx, &dvx, drive = drive(set)](Eigen::Index k, std::size_t, double* w,
                                                   double& y) {
    if (std::abs(vx(k)) < min_speed_ || braking[static_cast<std::size_t>(k)]) return false;
    if (slip_check && slipping[static_cast<std::size_t>(k)]) return false;
    const Drive d = drive(k);
    if (!std::isfinite(d.factor)) return false;  // no listed gear fits the inferred ratio
    w[0] = dvx(k);
    w[1] = half_rho * detail::signed_square(vx(k));
    w[2] = detail::sgn(vx(k));
    y = d.force;
    return true;
  };
}

}  // namespace dynid::model
