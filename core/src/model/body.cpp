#include "dynid/model/body.hpp"

#include <Eigen/Geometry>

#include "dynid/model/effects.hpp"
#include "support.hpp"

namespace dynid::model {

using detail::parameter;
using detail::positive;

namespace {

constexpr std::array<const char*, 4> kCorners{"fl", "fr", "rl", "rr"};
constexpr std::array<const char*, 6> kWrench{"fx", "fy", "fz", "mx", "my", "mz"};

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

// J v as a linear map of [XX XY XZ YY YZ ZZ] (J symmetric).
Eigen::Matrix<double, 3, 6> inertia_map(const Eigen::Vector3d& v) {
  Eigen::Matrix<double, 3, 6> l;
  l << v.x(), v.y(), v.z(), 0.0, 0.0, 0.0,  //
      0.0, v.x(), 0.0, v.y(), v.z(), 0.0,   //
      0.0, 0.0, v.x(), 0.0, v.y(), v.z();
  return l;
}

}  // namespace

BodyModel::BodyModel(const Constants& constants) {
  const ConstantReader c(constants, name());
  for (std::size_t i = 0; i < kCorners.size(); ++i) {
    const std::string corner = kCorners[i];
    const std::string meaning = "m, hub centre " + corner + " relative to the IMU point, body axes";
    hub_[i] = {c.required("hub_x_" + corner, meaning), c.required("hub_y_" + corner, meaning),
               c.required("hub_z_" + corner, meaning)};
  }
  air_density_ = c.optional("air_density");
}

std::vector<std::string> BodyModel::measured_side() const {
  std::vector<std::string> out;
  for (const char* corner : kCorners)
    for (const char* part : kWrench) out.push_back(std::string("hub_") + part + "_" + corner);
  return out;
}

std::vector<ParameterInfo> BodyModel::parameters() const {
  // Moments of inertia and the mass > 0; products of inertia and first moments take either
  // sign (they depend on where C and the axes are), so they have no bounds.
  return {positive(parameter("XX", "kg m^2", "roll inertia at C")),
          parameter("XY", "kg m^2", "inertia product at C"),
          parameter("XZ", "kg m^2", "inertia product at C"),
          positive(parameter("YY", "kg m^2", "pitch inertia at C")),
          parameter("YZ", "kg m^2", "inertia product at C"),
          positive(parameter("ZZ", "kg m^2", "yaw inertia at C")),
          parameter("MX", "kg m", "longitudinal first moment M x_G"),
          parameter("MY", "kg m", "lateral first moment M y_G"),
          parameter("MZ", "kg m", "vertical first moment M z_G"),
          positive(parameter("M", "kg", "mass"))};
}

std::vector<ChannelNeed> BodyModel::channels() const {
  std::vector<ChannelNeed> out{{"ax", "m/s^2"},           {"ay", "m/s^2"},
                               {"az", "m/s^2"},           {"roll_rate", "rad/s"},
                               {"pitch_rate", "rad/s"},   {"yaw_rate", "rad/s"},
                               {"d_roll_rate", "rad/s^2"}, {"d_pitch_rate", "rad/s^2"},
                               {"d_yaw_rate", "rad/s^2"}};
  for (const char* corner : kCorners)
    for (std::size_t j = 0; j < kWrench.size(); ++j)
      out.push_back({std::string("hub_") + kWrench[j] + "_" + corner, j < 3 ? "N" : "N m"});
  out.push_back({"vx", "m/s", true});
  return out;
}

Eigen::Matrix<double, 6, 10> BodyModel::regressor(const Eigen::Vector3d& a,
                                                  const Eigen::Vector3d& w,
                                                  const Eigen::Vector3d& dw) {
  Eigen::Matrix<double, 6, 10> d = Eigen::Matrix<double, 6, 10>::Zero();
  const Eigen::Matrix3d sw = skew(w);
  d.block<3, 3>(0, 6) = skew(dw) + sw * sw;  // dw x MS + w x (w x MS)
  d.block<3, 1>(0, 9) = a;                   // M a
  d.block<3, 6>(3, 0) = inertia_map(dw) + sw * inertia_map(w);  // J dw + w x (J w)
  d.block<3, 3>(3, 6) = -skew(a);                                // MS x a
  return d;
}

std::vector<RowModel::EffectDefinition> BodyModel::effect_definitions() const {
  EffectDefinition offset{{effect::kForceOffset,
                           "offsets of the summed hub force sensors (their moments neglected)",
                           {parameter("force_offset_x", "N", "", 0.0),
                            parameter("force_offset_y", "N", "", 0.0),
                            parameter("force_offset_z", "N", "", 0.0)},
                           {}},
                          [](const ChannelSet&) -> ColumnFn {
                            return [](Eigen::Index, std::size_t g, double* out) {
                              if (g < 3) out[g] = 1.0;
                              return true;
                            };
                          }};
  std::vector<EffectDefinition> out{offset};
  if (!air_density_) return out;
  const double half_rho = 0.5 * *air_density_;
  out.push_back(detail::one_column(
      {effect::kAeroDrag, "aerodynamic drag 1/2 rho SCx vx|vx| in the fx equation",
       {detail::drag_area("drag area")},
       {"vx"}},
      [half_rho](const ChannelSet& set) -> detail::ValueFn {
        const Eigen::VectorXd& vx = set["vx"];
        return [&vx, half_rho](Eigen::Index k) { return half_rho * detail::signed_square(vx(k)); };
      }));
  return out;
}

RowModel::RowFn BodyModel::bind(const ChannelSet& set, const std::vector<std::string>&) const {
  std::vector<const Eigen::VectorXd*> motion;
  for (const char* c : {"ax", "ay", "az", "roll_rate", "pitch_rate", "yaw_rate", "d_roll_rate",
                        "d_pitch_rate", "d_yaw_rate"})
    motion.push_back(&set[c]);
  std::vector<const Eigen::VectorXd*> hubs;  // per corner: fx fy fz mx my mz
  for (const char* corner : kCorners)
    for (const char* part : kWrench) hubs.push_back(&set[std::string("hub_") + part + "_" + corner]);
  // The regressor and the wrench of the last sample: the six groups of a sample come one after
  // the other (RowModel::RowFn), so each sample's are computed once, not once per group.
  Eigen::Index cached = -1;
  Eigen::Matrix<double, 6, 10> d = Eigen::Matrix<double, 6, 10>::Zero();
  Eigen::Matrix<double, 6, 1> wrench = Eigen::Matrix<double, 6, 1>::Zero();
  return [motion, hubs, hub = hub_, cached, d, wrench](Eigen::Index k, std::size_t group, double* w,
                                                       double& y) mutable {
    if (k != cached) {
      auto at = [&](std::size_t i) { return (*motion[i])(k); };
      d = regressor({at(0), at(1), at(2)}, {at(3), at(4), at(5)}, {at(6), at(7), at(8)});
      wrench.setZero();
      for (std::size_t c = 0; c < hub.size(); ++c) {
        auto part = [&](std::size_t j) { return (*hubs[6 * c + j])(k); };
        const Eigen::Vector3d f(part(0), part(1), part(2));
        wrench.head<3>() += f;
        wrench.tail<3>() += Eigen::Vector3d(part(3), part(4), part(5)) + hub[c].cross(f);
      }
      cached = k;
    }
    Eigen::Map<Eigen::Matrix<double, 1, 10>> columns(w);
    columns = d.row(static_cast<Eigen::Index>(group));
    y = wrench(static_cast<Eigen::Index>(group));
    return true;
  };
}

}  // namespace dynid::model
