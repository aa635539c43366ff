#include "dynid/model/registry.hpp"

#include <functional>
#include <map>

#include "dynid/error.hpp"
#include "dynid/model/body.hpp"
#include "dynid/model/clutch_slip.hpp"
#include "dynid/model/clutch_torque_curve.hpp"
#include "dynid/model/kinematic.hpp"
#include "dynid/model/lateral_bicycle.hpp"
#include "dynid/model/lateral_no_vy.hpp"
#include "dynid/model/locked_driveline.hpp"
#include "dynid/model/longitudinal.hpp"
#include "dynid/model/suspension.hpp"
#include "dynid/model/tyre_vertical.hpp"

namespace dynid::model {
namespace {

using Factory = std::function<std::unique_ptr<Model>(const Constants&)>;

template <typename M, typename... Args>
Factory factory(Args... args) {
  return [=](const Constants& c) { return std::make_unique<M>(c, args...); };
}

const std::map<std::string, Factory>& registry() {
  using Lon = LongitudinalModel;
  using Kin = KinematicModel;
  static const std::map<std::string, Factory> r{
      {"longitudinal_engine", factory<Lon>(Lon::Source::kEngineTorque)},
      {"longitudinal_wheel", factory<Lon>(Lon::Source::kWheelTorque)},
      {"lateral_bicycle", factory<LateralBicycleModel>()},
      {"lateral_bicycle_no_vy", factory<LateralNoVyModel>()},
      {"kinematic_longitudinal", factory<Kin>(Kin::Axis::kLongitudinal)},
      {"kinematic_lateral", factory<Kin>(Kin::Axis::kLateral)},
      {"body", factory<BodyModel>()},
      {"suspension_fl", factory<SuspensionModel>(std::string("fl"))},
      {"suspension_fr", factory<SuspensionModel>(std::string("fr"))},
      {"suspension_rl", factory<SuspensionModel>(std::string("rl"))},
      {"suspension_rr", factory<SuspensionModel>(std::string("rr"))},
      {"tyre_fl", factory<TyreVerticalModel>(std::string("fl"))},
      {"tyre_fr", factory<TyreVerticalModel>(std::string("fr"))},
      {"tyre_rl", factory<TyreVerticalModel>(std::string("rl"))},
      {"tyre_rr", factory<TyreVerticalModel>(std::string("rr"))},
      {"clutch_slip", factory<ClutchSlipModel>()},
      {"clutch_torque_curve", factory<ClutchTorqueCurveModel>()},
      {"locked_driveline", factory<LockedDrivelineModel>()}};
  return r;
}

}  // namespace

std::unique_ptr<Model> make_model(const std::string& name, const Constants& constants) {
  const auto it = registry().find(name);
  if (it == registry().end()) {
    std::string known;
    for (const std::string& n : model_names()) known += " " + n;
    throw InputError("unknown model '" + name + "' (known:" + known + ")");
  }
  return it->second(constants);
}

std::vector<std::string> model_names() {
  std::vector<std::string> out;
  for (const auto& [name, f] : registry()) out.push_back(name);
  return out;
}

}  // namespace dynid::model
