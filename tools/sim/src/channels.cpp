#include "dynid/sim/channels.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

#include "dynid/error.hpp"
#include "dynid/model/channel_catalogue.hpp"

namespace dynid::sim {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// Body -> yaw frame rotation R = Ry(pitch) Rx(roll) applied to v, and its transpose.
Vec3 rotate_to_yaw_frame(const Vec3& v, double roll, double pitch) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  const Vec3 a{v[0], cr * v[1] - sr * v[2], sr * v[1] + cr * v[2]};  // Rx
  return {cp * a[0] + sp * a[2], a[1], -sp * a[0] + cp * a[2]};       // Ry
}
Vec3 rotate_to_body(const Vec3& v, double roll, double pitch) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  const Vec3 a{cp * v[0] - sp * v[2], v[1], sp * v[0] + cp * v[2]};  // Ry^T
  return {a[0], cr * a[1] + sr * a[2], -sr * a[1] + cr * a[2]};       // Rx^T
}

// The channels the simulator writes, in the CSV column order that true_channel_values()
// follows. Units come from the project's one catalogue (docs/CHANNELS.md as code).
std::vector<std::string> written_channel_names() {
  std::vector<std::string> c{"vx", "vy"};
  for (const char* w : kCornerNames) c.push_back(std::string("wheel_speed_") + w);
  c.insert(c.end(), {"ax", "ay", "az", "roll_rate", "pitch_rate", "yaw_rate", "steer",
                     "engine_speed", "engine_torque", "gearbox_input_speed", "gear", "gear_ratio",
                     "clutch_clamp_load", "wheel_torque", "brake_pressure", "road_grade",
                     "road_bank"});
  for (const char* w : kCornerNames) c.push_back(std::string("susp_travel_") + w);
  for (const char* w : kCornerNames) c.push_back(std::string("susp_force_") + w);
  for (const char* w : kCornerNames)
    for (const char* f : {"hub_fx_", "hub_fy_", "hub_fz_"}) c.push_back(std::string(f) + w);
  for (const char* w : kCornerNames) c.push_back(std::string("tyre_deflection_") + w);
  for (const char* w : kCornerNames) c.push_back(std::string("tyre_force_z_") + w);
  c.push_back("roll");
  return c;
}

std::vector<ChannelInfo> make_catalogue() {
  std::vector<ChannelInfo> c;
  for (auto& name : written_channel_names()) {
    const auto unit = model::channel_unit(name);
    if (!unit) throw std::logic_error("simulator channel '" + name + "' is not in the catalogue");
    c.push_back({name, *unit});
  }
  return c;
}

// Specific force at the IMU point, body axes.
Vec3 imu_specific_force(const VehicleParameters& v, const State& s, const Evaluation& e) {
  const State& ds = e.derivative;
  const Vec3 w{s[kDphi], s[kDtheta], s[kR]};
  const Vec3 dw{ds[kDphi], ds[kDtheta], ds[kR]};
  const Vec3 p = rotate_to_yaw_frame(v.imu_position, s[kPhi], s[kTheta]);
  const Vec3 a_o{ds[kVx] - s[kR] * s[kVy], ds[kVy] + s[kR] * s[kVx], ds[kDz]};
  const Vec3 t1 = cross(dw, p);
  const Vec3 t2 = cross(w, cross(w, p));
  Vec3 f{};
  for (std::size_t i = 0; i < 3; ++i) f[i] = a_o[i] + t1[i] + t2[i] - e.gravity[i];
  return rotate_to_body(f, s[kPhi], s[kTheta]);
}

}  // namespace

const std::vector<ChannelInfo>& channel_catalogue() {
  static const std::vector<ChannelInfo> catalogue = make_catalogue();
  return catalogue;
}

std::size_t channel_index(std::string_view name) {
  const auto& c = channel_catalogue();
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c[i].name == name) return i;
  throw InputError("channel '" + std::string(name) + "' is not one the simulator writes");
}

std::vector<double> true_channel_values(const CarModel& model, const State& s,
                                        const DriverInputs& in, const Evaluation& e) {
  const auto& v = model.car.vehicle;
  std::vector<double> out;
  out.reserve(channel_catalogue().size());
  double mean_wheel = 0.0;
  for (double ws : e.wheel_speed) mean_wheel += 0.25 * ws;
  out.push_back(mean_wheel);
  out.push_back(s[kVy]);
  for (double ws : e.wheel_speed) out.push_back(ws);
  const Vec3 f = imu_specific_force(v, s, e);
  out.insert(out.end(), f.begin(), f.end());
  // Gyros: Euler rates (roll, pitch, yaw) to body rates.
  const double phi = s[kPhi], th = s[kTheta];
  out.push_back(s[kDphi] - s[kR] * std::sin(th));
  out.push_back(s[kDtheta] * std::cos(phi) + s[kR] * std::sin(phi) * std::cos(th));
  out.push_back(-s[kDtheta] * std::sin(phi) + s[kR] * std::cos(phi) * std::cos(th));
  out.push_back(in.steer);
  out.push_back(s[kWEngine]);
  out.push_back(e.engine_torque);
  out.push_back(s[kWInput]);
  out.push_back(in.gear);
  out.push_back(model.car.driveline.ratio(in.gear));
  out.push_back(in.clamp_load);
  out.push_back(e.shaft_torque);
  out.push_back(in.brake_pressure);
  out.push_back(e.grade);
  out.push_back(e.bank);
  out.insert(out.end(), e.travel.begin(), e.travel.end());
  out.insert(out.end(), e.suspension_force.begin(), e.suspension_force.end());
  for (std::size_t k = 0; k < kCorners; ++k) {
    out.push_back(e.tyre_fx[k]);
    out.push_back(e.tyre_fy[k]);
    out.push_back(e.tyre_load[k]);
  }
  out.insert(out.end(), e.tyre_deflection.begin(), e.tyre_deflection.end());
  out.insert(out.end(), e.tyre_load.begin(), e.tyre_load.end());
  // Body roll to the road as a pair of ride-height lasers per axle sees it: the suspension and
  // tyre compressions, right minus left, over the track, averaged over the axles (corners
  // fl, fr, rl, rr; both positive in compression, so positive is right side down).
  const auto axle_roll = [&](std::size_t left, std::size_t right, double track) {
    return ((e.travel[right] - e.travel[left]) + (e.tyre_deflection[right] - e.tyre_deflection[left])) / track;
  };
  out.push_back(0.5 * (axle_roll(0, 1, v.track_front) + axle_roll(2, 3, v.track_rear)));
  return out;
}

}  // namespace dynid::sim
