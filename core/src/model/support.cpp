#include "support.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/error.hpp"
#include "dynid/model/effects.hpp"

namespace dynid::model::detail {

RowModel::EffectDefinition one_column(Effect info, std::function<ValueFn(const ChannelSet&)> bind,
                                      std::size_t group) {
  RowModel::EffectDefinition def{std::move(info), {}};
  def.bind = [bind = std::move(bind), group](const ChannelSet& set) -> RowModel::ColumnFn {
    ValueFn value = bind(set);
    return [value = std::move(value), group](Eigen::Index k, std::size_t g, double* out) {
      if (g == group) out[0] = value(k);
      return true;
    };
  };
  return def;
}

}  // namespace dynid::model::detail

namespace dynid::model::detail {

std::function<bool(Eigen::Index)> braking(const ChannelSet& set, double threshold, bool allowed) {
  const Eigen::VectorXd* p = find(set, "brake_pressure");
  if (p == nullptr || allowed) return [](Eigen::Index) { return false; };
  return [p, threshold](Eigen::Index k) { return (*p)(k) > threshold; };
}

ValueFn channel(const ChannelSet& set, const std::string& name) {
  const Eigen::VectorXd& x = set[name];
  return [&x](Eigen::Index k) { return x(k); };
}

std::function<bool(Eigen::Index)> clutch_sticks(const ChannelSet& set, double min_slip) {
  return [&we = set["engine_speed"], &wi = set["gearbox_input_speed"], min_slip](Eigen::Index k) {
    return std::abs(we(k) - wi(k)) < min_slip;
  };
}

RowModel::EffectDefinition clutch_torque_offset() {
  return one_column(
      {effect::kTorqueOffset,
       "ECU engine torque offset (true = ECU + T0)",
       {measures(parameter("engine_torque_offset", "N m", "T0", 0.0), "engine_torque_offset")},
       {}},
      [](const ChannelSet&) { return ValueFn([](Eigen::Index) { return -1.0; }); });
}

RowModel::EffectDefinition brake_drag(const std::string& parameter_name, const std::string& unit) {
  return one_column({"brake_drag",
                     "brake force or torque proportional to brake pressure",
                     // >= 0: the brake resists (the column is on the resisting side).
                     {non_negative(parameter(parameter_name, unit, "brake gain"))},
                     {"brake_pressure"}},
                    [](const ChannelSet& set) { return channel(set, "brake_pressure"); });
}

}  // namespace dynid::model::detail

namespace dynid::model::detail {

std::string opposite_corner(const std::string& corner, const std::string& model) {
  if (corner == "fl") return "fr";
  if (corner == "fr") return "fl";
  if (corner == "rl") return "rr";
  if (corner == "rr") return "rl";
  throw InputError("model '" + model + "': unknown corner '" + corner + "' (fl, fr, rl, rr)");
}

std::vector<bool> within_margin_of(Eigen::Index samples, Eigen::Index margin,
                                   const std::function<bool(Eigen::Index)>& flagged) {
  std::vector<bool> out(static_cast<std::size_t>(samples), false);
  for (Eigen::Index k = 0; k < samples; ++k) {
    if (!flagged(k)) continue;
    for (Eigen::Index j = std::max<Eigen::Index>(0, k - margin); j <= std::min(samples - 1, k + margin); ++j)
      out[static_cast<std::size_t>(j)] = true;
  }
  return out;
}

Eigen::Index margin_samples(double margin_s, double sample_period) {
  return static_cast<Eigen::Index>(std::ceil(margin_s / sample_period - 1e-9));
}

double optional_margin(const ConstantReader& c, const std::string& name) {
  const double margin = c.optional(name).value_or(0.0);
  // A negative margin is an error: positive() throws naming the constant.
  return margin < 0.0 ? c.positive(name, "s, >= 0") : margin;
}

double brake_pressure_threshold(const ConstantReader& c) {
  return c.positive_or("brake_pressure_threshold", 2e4);
}

std::vector<bool> near_braking(const ChannelSet& set, double threshold, double margin_s,
                               bool allowed) {
  return within_margin_of(set.samples(), margin_samples(margin_s, set.sample_period()),
                          braking(set, threshold, allowed));
}

RowReach widened(RowReach r, double margin_s, double sample_period) {
  const Eigen::Index margin = margin_samples(margin_s, sample_period);
  r.back = std::max(r.back, margin);
  r.ahead = std::max(r.ahead, margin);
  return r;
}

}  // namespace dynid::model::detail
