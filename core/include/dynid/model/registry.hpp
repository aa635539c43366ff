#pragma once
// The model registry: a model by name from a vehicle profile's constants (constants.hpp).
//
//   longitudinal_engine, longitudinal_wheel   LongitudinalModel (longitudinal.hpp)
//   lateral_bicycle                           LateralBicycleModel (lateral_bicycle.hpp)
//   kinematic_longitudinal, kinematic_lateral KinematicModel (kinematic.hpp)
//   body                                      BodyModel (body.hpp)
//   suspension_fl .. suspension_rr            SuspensionModel (suspension.hpp)
//   tyre_fl .. tyre_rr                        TyreVerticalModel (tyre_vertical.hpp)
//   clutch_slip                               ClutchSlipModel (clutch_slip.hpp)
//   locked_driveline                          LockedDrivelineModel (constant `gear` selects it)
//
// Each model's header lists the constants it reads. An unknown name, a missing constant or a
// constant out of range throws InputError naming the model and the constant. Models are
// immutable: the result may be shared by threads.
#include <memory>
#include <string>
#include <vector>

#include "dynid/model/constants.hpp"
#include "dynid/model/model.hpp"

namespace dynid::model {

std::unique_ptr<Model> make_model(const std::string& name, const Constants& constants);
std::vector<std::string> model_names();

}  // namespace dynid::model
