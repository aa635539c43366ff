// Vehicle models (longitudinal, lateral bicycle, kinematic, body 6x10): each recovers its
// parameters to 1e-6 relative from noise-free data made with its own equations.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "dynid/error.hpp"
#include "dynid/ls/equation_groups.hpp"
#include "dynid/model/body.hpp"
#include "dynid/model/channel_set.hpp"
#include "dynid/model/registry.hpp"
#include "model_test_support.hpp"

namespace dynid::test {
namespace {

constexpr double kG = 9.80665;

// Longitudinal truth (a mid-size car: test data, not model code).
constexpr double kMass = 1500.0, kSCx = 0.65, kRolling = 180.0, kRho = 1.2, kRadius = 0.31,
                 kEta = 0.92;

struct LongitudinalRun {
  model::ChannelSet set;
  Eigen::VectorXd force;  // the true drive force
};

// vx from sines with its exact derivative; the drive force from the model's own balance; a
// braking stretch (brake_pressure > 0) where the torque is nonsense and must be masked.
LongitudinalRun longitudinal_run(double grade_amplitude) {
  const Eigen::Index n = 3000;
  const Eigen::VectorXd t = time_grid(0.02, n);
  const Sines v{22.0, {6.0, 2.0}, {0.21, 0.9}, {0.0, 0.7}};
  const Sines grade{0.0, {grade_amplitude}, {0.13}, {0.3}};
  LongitudinalRun run{model::ChannelSet(0.02, n), Eigen::VectorXd(n)};
  const Eigen::VectorXd vx = v.values(t), dvx = v.derivatives(t), theta = grade.values(t);
  Eigen::VectorXd pressure = Eigen::VectorXd::Zero(n);
  pressure.segment(1000, 200).setConstant(3e6);
  for (Eigen::Index k = 0; k < n; ++k)
    run.force(k) = kMass * dvx(k) + 0.5 * kRho * kSCx * vx(k) * std::abs(vx(k)) + kRolling +
                   kMass * kG * std::sin(theta(k));
  run.set.add("vx", "m/s", vx);
  run.set.add("d_vx", "m/s^2", dvx);
  run.set.add("brake_pressure", "Pa", pressure);
  run.set.add("road_grade", "rad", theta);
  run.set.add("ax", "m/s^2", dvx + kG * theta.array().sin().matrix());
  return run;
}

TEST(Longitudinal, EngineTorqueRecoversMassDragRollingAndGrade) {
  LongitudinalRun run = longitudinal_run(0.03);
  const Eigen::Index n = run.set.samples();
  const Eigen::VectorXd t = time_grid(0.02, n);
  Eigen::VectorXd ratio(n), torque(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    ratio(k) = t(k) < 20.0 ? 8.9 : (t(k) < 40.0 ? 6.1 : 4.5);
    // Driving: F = eta T G / r; dragging: F = T G / (eta r).
    const double f = run.force(k);
    torque(k) = f >= 0 ? f * kRadius / (kEta * ratio(k)) : f * kRadius * kEta / ratio(k);
  }
  torque.segment(1000, 200).setConstant(-999.0);  // braking: not the model, must be masked
  run.set.add("engine_torque", "N m", torque);
  run.set.add("gear_ratio", "-", ratio);
  const auto m = model::make_model(
      "longitudinal_engine",
      {{"wheel_radius", kRadius}, {"air_density", kRho}, {"driveline_efficiency", kEta}});
  const Identified id = identify(*m, run.set, {"road_grade"});
  EXPECT_EQ(id.rows, static_cast<std::size_t>(n - 200));
  expect_recovered(id, {{"mass", kMass}, {"SCx", kSCx}, {"rolling_resistance", kRolling},
                        {"grade_mass", kMass}});
  // The accelerometer sees the same grade.
  expect_recovered(identify(*m, run.set, {"road_grade_accelerometer"}),
                   {{"mass", kMass}, {"grade_mass_accelerometer", kMass}});
}

// A bus without a gear ratio (a manual car): the gears' ratios given as constants, the ratio of
// each row is inferred from engine_speed r_w / vx; a shift (the engine between two gears' speeds)
// and neutral are left out, and the truth comes back exactly, with the rotating inertia too.
TEST(Longitudinal, TheGearInferredFromTheEngineSpeedRecoversTheTruth) {
  LongitudinalRun run = longitudinal_run(0.0);
  const Eigen::Index n = run.set.samples();
  const Eigen::VectorXd t = time_grid(0.02, n);
  constexpr double kEngineInertia = 0.2;  // kg m^2
  const Eigen::VectorXd& vx = run.set["vx"];
  const Eigen::VectorXd& dvx = run.set["d_vx"];
  Eigen::VectorXd torque(n), engine(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double ratio = t(k) < 20.0 ? 8.9 : (t(k) < 40.0 ? 6.1 : 4.5);
    engine(k) = ratio * vx(k) / kRadius;
    // The engine's torque: what reaches the wheels through the driveline (the factor of its
    // sign, eta G / r driving, G / (eta r) dragging) and what accelerates its own inertia.
    const double inertia = kEngineInertia * ratio / kRadius * dvx(k);
    const double driving = run.force(k) * kRadius / (kEta * ratio) + inertia;
    torque(k) = driving >= 0.0 ? driving : run.force(k) * kRadius * kEta / ratio + inertia;
    ASSERT_EQ(torque(k) >= 0.0, driving >= 0.0) << k;  // the sign decides the factor: one answer
  }
  torque.segment(1000, 200).setConstant(-999.0);  // braking
  engine.segment(1500, 10).array() *= 7.5 / 6.1;  // a shift: between 6.1 and 8.9, 19 % off each
  torque.segment(1500, 10).setConstant(-999.0);
  engine.segment(2500, 10).setConstant(80.0);  // neutral: idling at 100 km/h
  torque.segment(2500, 10).setConstant(-999.0);
  run.set.add("engine_torque", "N m", torque);
  run.set.add("engine_speed", "rad/s", engine);
  const auto m = model::make_model("longitudinal_engine", {{"wheel_radius", kRadius},
                                                           {"air_density", kRho},
                                                           {"driveline_efficiency", kEta},
                                                           {"gear_ratio_1", 8.9},
                                                           {"gear_ratio_2", 6.1},
                                                           {"gear_ratio_3", 4.5}});
  EXPECT_TRUE(m->can_run_on(run.set));  // no gear_ratio channel
  const Identified id = identify(*m, run.set, {"rotating_inertia"});
  EXPECT_EQ(id.rows, static_cast<std::size_t>(n - 200 - 20));
  expect_recovered(id, {{"mass", kMass},
                        {"SCx", kSCx},
                        {"rolling_resistance", kRolling},
                        {"engine_inertia", kEngineInertia}});
  // With a gear channel, its neutral is a coast (no drive force), not a slipping clutch: those
  // rows are kept.
  Eigen::VectorXd gear = Eigen::VectorXd::Constant(n, 3.0);
  gear.segment(2500, 10).setZero();
  model::ChannelSet with_gear = run.set;
  with_gear.add("gear", "-", gear);
  const Identified neutral = identify(*m, with_gear, {"rotating_inertia"});
  EXPECT_EQ(neutral.rows, static_cast<std::size_t>(n - 200 - 10));
}

// A clutch that slips for 0.1 s (a shift): with clutch_slip_margin the rows within that long of
// a slipping sample are left out too, and reach() says how far a row reads.
TEST(Longitudinal, TheSlipMarginLeavesOutTheRowsAroundASlippingClutch) {
  LongitudinalRun run = longitudinal_run(0.0);
  const Eigen::Index n = run.set.samples();
  Eigen::VectorXd ratio = Eigen::VectorXd::Constant(n, 6.1), torque(n), engine(n), input(n);
  for (Eigen::Index k = 0; k < n; ++k) {  // driving: F = eta T G / r; dragging: F = T G / (eta r)
    const double f = run.force(k);
    torque(k) = f >= 0 ? f * kRadius / (kEta * 6.1) : f * kRadius * kEta / 6.1;
  }
  engine.setConstant(200.0);
  input.setConstant(200.0);
  input.segment(2000, 5).setConstant(150.0);  // 5 samples of 0.02 s slip
  torque.segment(2000, 5).setConstant(-999.0);
  run.set.add("engine_torque", "N m", torque);
  run.set.add("gear_ratio", "-", ratio);
  run.set.add("engine_speed", "rad/s", engine);
  run.set.add("gearbox_input_speed", "rad/s", input);
  const model::Constants constants{{"wheel_radius", kRadius}, {"air_density", kRho}, {"driveline_efficiency", kEta}};
  const Identified plain = identify(*model::make_model("longitudinal_engine", constants), run.set);
  EXPECT_EQ(plain.rows, static_cast<std::size_t>(n - 200 - 5));
  model::Constants with_margin = constants;
  with_margin["clutch_slip_margin"] = 0.1;  // 5 samples each side
  const auto m = model::make_model("longitudinal_engine", with_margin);
  const Identified margin = identify(*m, run.set);
  EXPECT_EQ(margin.rows, static_cast<std::size_t>(n - 200 - 15));
  expect_recovered(margin, {{"mass", kMass}, {"SCx", kSCx}, {"rolling_resistance", kRolling}});
  EXPECT_GE(m->reach(0.02).back, 5);
  EXPECT_GE(m->reach(0.02).ahead, 5);
  model::Constants negative = constants;
  negative["clutch_slip_margin"] = -0.1;
  EXPECT_THROW(model::make_model("longitudinal_engine", negative), InputError);
}

TEST(Longitudinal, WheelTorqueRecoversOnFlatRoad) {
  LongitudinalRun run = longitudinal_run(0.0);
  run.set.add("wheel_torque", "N m", run.force * kRadius);
  const auto m =
      model::make_model("longitudinal_wheel", {{"wheel_radius", kRadius}, {"air_density", kRho}});
  expect_recovered(identify(*m, run.set),
                   {{"mass", kMass}, {"SCx", kSCx}, {"rolling_resistance", kRolling}});
}

// The brake force smeared by the low-pass into the rows just before and after a braking stretch
// (their own pressure below the threshold): with brake_margin the rows within that long of a
// braking sample are left out too, for both sources, and reach() says how far a row reads.
TEST(Longitudinal, TheBrakeMarginLeavesOutTheRowsAroundBraking) {
  LongitudinalRun run = longitudinal_run(0.0);
  const Eigen::Index n = run.set.samples();
  Eigen::VectorXd torque = run.force * kRadius;
  torque.segment(995, 5).array() += 900.0;  // the brake's force in the 5 rows before it (0.1 s)
  torque.segment(1200, 5).array() += 900.0;  // and after it
  run.set.add("wheel_torque", "N m", torque);
  const model::Constants constants{{"wheel_radius", kRadius}, {"air_density", kRho}};
  const Identified plain = identify(*model::make_model("longitudinal_wheel", constants), run.set);
  EXPECT_EQ(plain.rows, static_cast<std::size_t>(n - 200));
  EXPECT_GT(relative_error(plain.value("SCx"), kSCx), 1e-4);
  model::Constants with_margin = constants;
  with_margin["brake_margin"] = 0.1;  // 5 samples each side
  const auto m = model::make_model("longitudinal_wheel", with_margin);
  const Identified margin = identify(*m, run.set);
  EXPECT_EQ(margin.rows, static_cast<std::size_t>(n - 200 - 10));
  expect_recovered(margin, {{"mass", kMass}, {"SCx", kSCx}, {"rolling_resistance", kRolling}});
  EXPECT_GE(m->reach(0.02).back, 5);
  EXPECT_GE(m->reach(0.02).ahead, 5);
  model::Constants negative = constants;
  negative["brake_margin"] = -0.1;
  EXPECT_THROW(model::make_model("longitudinal_wheel", negative), InputError);
}

// A wheel-torque meter reading T0 at zero torque: the tare's zero, given as the constant
// wheel_torque_zero, gives the exact recovery back.
TEST(Longitudinal, WheelTorqueZeroFromTheTareIsSubtracted) {
  LongitudinalRun run = longitudinal_run(0.0);
  const double t0 = -23.5;
  run.set.add("wheel_torque", "N m", Eigen::VectorXd(run.force.array() * kRadius + t0));
  const auto m = model::make_model("longitudinal_wheel",
                                   {{"wheel_radius", kRadius}, {"air_density", kRho}, {"wheel_torque_zero", t0}});
  expect_recovered(identify(*m, run.set), {{"mass", kMass}, {"SCx", kSCx}, {"rolling_resistance", kRolling}});
}

// Lateral bicycle truth (a, b: venture §6.0 Peugeot 406 geometry; stiffnesses: test values).
constexpr double kA = 1.09, kB = 1.60, kYaw = 2342.0, kCf = 90000.0, kCr = 110000.0,
                 kImuX = -0.4;

// Integrates the bicycle (RK4) under a steer input at varying speed; at every sample the
// derivative is the model's right-hand side, so the equations hold exactly at the samples.
model::ChannelSet bicycle_run() {
  const Eigen::Index n = 4000;
  const double dt = 0.01;
  const Sines steer{0.0, {0.04, 0.015}, {0.9, 2.7}, {0.0, 0.4}};
  const Sines speed{18.0, {5.0}, {0.1}, {0.0}};
  auto rhs = [&](double t, const Eigen::Vector2d& s, double* ay) {
    const double vx = speed.value(t), d = steer.value(t);
    const double df = d - std::atan((s(0) + kA * s(1)) / vx);
    const double dr = -std::atan((s(0) - kB * s(1)) / vx);
    const double fyf = kCf * df * std::cos(d), fyr = kCr * dr;
    if (ay != nullptr) *ay = (fyf + fyr) / kMass;
    return Eigen::Vector2d((fyf + fyr) / kMass - s(1) * vx, (kA * fyf - kB * fyr) / kYaw);
  };
  model::ChannelSet set(dt, n);
  Eigen::VectorXd vx(n), vy(n), r(n), dr(n), ay(n), st(n);
  Eigen::Vector2d s(0.0, 0.0);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = dt * static_cast<double>(k);
    double a = 0.0;
    const Eigen::Vector2d f = rhs(t, s, &a);
    vx(k) = speed.value(t), vy(k) = s(0), r(k) = s(1), dr(k) = f(1), st(k) = steer.value(t);
    ay(k) = a + kImuX * f(1);  // the IMU sits imu_x ahead of the CG
    const Eigen::Vector2d k1 = f, k2 = rhs(t + dt / 2, s + dt / 2 * k1, nullptr),
                          k3 = rhs(t + dt / 2, s + dt / 2 * k2, nullptr),
                          k4 = rhs(t + dt, s + dt * k3, nullptr);
    s += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  set.add("vx", "m/s", vx);
  set.add("vy", "m/s", vy);
  set.add("yaw_rate", "rad/s", r);
  set.add("d_yaw_rate", "rad/s^2", dr);
  set.add("ay", "m/s^2", ay);
  set.add("steer", "rad", st);
  return set;
}

TEST(LateralBicycle, KnownMassRecoversYawInertiaAndCorneringStiffness) {
  const model::ChannelSet set = bicycle_run();
  const auto m =
      model::make_model("lateral_bicycle", {{"a", kA}, {"b", kB}, {"mass", kMass}, {"imu_x", kImuX}});
  expect_recovered(identify(*m, set), {{"yaw_inertia", kYaw},
                                       {"front_cornering_stiffness", kCf},
                                       {"rear_cornering_stiffness", kCr}});
}

TEST(LateralBicycle, UnknownMassRecoversPerUnitMassQuantities) {
  const model::ChannelSet set = bicycle_run();
  const auto m = model::make_model("lateral_bicycle", {{"a", kA}, {"b", kB}, {"imu_x", kImuX}});
  expect_recovered(identify(*m, set), {{"yaw_inertia_per_mass", kYaw / kMass},
                                       {"front_cornering_stiffness_per_mass", kCf / kMass},
                                       {"rear_cornering_stiffness_per_mass", kCr / kMass}});
}

// A body-fixed accelerometer on a rolling body reads ay cos(roll) + az sin(roll) (az ~ +g): with
// the roll channel the model turns it back to the road plane and recovers the truth exactly.
TEST(LateralBicycle, RollChannelRemovesGravityFromTheAccelerometer) {
  const model::ChannelSet clean = bicycle_run();
  const Eigen::Index n = clean.samples();
  model::ChannelSet set(clean.sample_period(), n);
  for (const auto& name : clean.names())
    if (name != "ay") set.add(name, clean.unit(name), clean[name]);
  Eigen::VectorXd roll(n), ay(n), az(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    roll(k) = 0.006 * clean["ay"](k) + 0.004 * clean["d_yaw_rate"](k);  // any roll history
    az(k) = kG + 0.3 * std::sin(0.01 * static_cast<double>(k));        // heave too
    // Specific force in the road plane (y_road, z_road) seen in body axes rolled by `roll`:
    // z_road = az cos - ay sin, and y_road = ay cos - az sin must equal the clean ay.
    const double c = std::cos(roll(k)), sn = std::sin(roll(k));
    ay(k) = (clean["ay"](k) + az(k) * sn) / c;
  }
  set.add("ay", "m/s^2", ay);
  set.add("az", "m/s^2", az);
  set.add("roll", "rad", roll);
  const auto m =
      model::make_model("lateral_bicycle", {{"a", kA}, {"b", kB}, {"mass", kMass}, {"imu_x", kImuX}});
  expect_recovered(identify(*m, set), {{"yaw_inertia", kYaw},
                                       {"front_cornering_stiffness", kCf},
                                       {"rear_cornering_stiffness", kCr}});
}

// Constant slip-angle offsets e_f, e_r on both axles (what steer, vy and yaw-rate sensor
// offsets give at a steady speed): slip_offset recovers C_f e_f and C_r e_r exactly.
// The rolling body: the lateral force also accelerates what the IMU does not see roll (or an
// IMU off the rolling CG reads h d2phi/dt2 too much), and J_xz couples roll into yaw. With the
// effect roll_acceleration both coefficients and the truth come back exactly.
TEST(LateralBicycle, RollAccelerationRecoversRollCouplings) {
  const model::ChannelSet clean = bicycle_run();
  const Eigen::Index n = clean.samples();
  const Eigen::VectorXd t = time_grid(clean.sample_period(), n);
  const Sines roll_rate{0.0, {0.05, 0.02}, {0.7, 1.9}, {0.1, 0.4}};
  const Eigen::VectorXd p = roll_rate.values(t), dp = roll_rate.derivatives(t);
  constexpr double kLateral = 85.0, kYawProduct = -45.0;  // kg m, kg m^2
  model::ChannelSet set(clean.sample_period(), n);
  for (const auto& name : clean.names())
    if (name != "ay" && name != "d_yaw_rate") set.add(name, clean.unit(name), clean[name]);
  // Rows: M (ay - imu_x dr) = F_y + kLateral dp;  0 = J dr - a F_yf + b F_yr + kYawProduct dp.
  const Eigen::VectorXd dr = clean["d_yaw_rate"] - (kYawProduct / kYaw) * dp;
  const Eigen::VectorXd ay = clean["ay"] + kImuX * (dr - clean["d_yaw_rate"]) + (kLateral / kMass) * dp;
  set.add("d_yaw_rate", "rad/s^2", dr);
  set.add("ay", "m/s^2", ay);
  set.add("roll_rate", "rad/s", p);
  set.add("d_roll_rate", "rad/s^2", dp);
  const auto m =
      model::make_model("lateral_bicycle", {{"a", kA}, {"b", kB}, {"mass", kMass}, {"imu_x", kImuX}});
  expect_recovered(identify(*m, set, {"roll_acceleration"}),
                   {{"yaw_inertia", kYaw},
                    {"front_cornering_stiffness", kCf},
                    {"rear_cornering_stiffness", kCr},
                    {"roll_lateral_moment", kLateral},
                    {"roll_yaw_product", kYawProduct}});
}

TEST(LateralBicycle, SlipOffsetRecoversConstantSlipAngleOffsets) {
  const model::ChannelSet clean = bicycle_run();
  const Eigen::Index n = clean.samples();
  constexpr double kEf = 0.002, kEr = -0.001;
  model::ChannelSet set(clean.sample_period(), n);
  for (const auto& name : clean.names())
    if (name != "ay" && name != "d_yaw_rate") set.add(name, clean.unit(name), clean[name]);
  // The car's forces carry the offsets; ay and dr/dt are those of the true forces.
  Eigen::VectorXd ay(n), dr(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double vx = clean["vx"](k), vy = clean["vy"](k), r = clean["yaw_rate"](k), d = clean["steer"](k);
    const double fyf = kCf * (d - std::atan((vy + kA * r) / vx) + kEf) * std::cos(d);
    const double fyr = kCr * (-std::atan((vy - kB * r) / vx) + kEr);
    dr(k) = (kA * fyf - kB * fyr) / kYaw;
    ay(k) = (fyf + fyr) / kMass + kImuX * dr(k);
  }
  set.add("ay", "m/s^2", ay);
  set.add("d_yaw_rate", "rad/s^2", dr);
  const auto m =
      model::make_model("lateral_bicycle", {{"a", kA}, {"b", kB}, {"mass", kMass}, {"imu_x", kImuX}});
  expect_recovered(identify(*m, set, {"slip_offset"}),
                   {{"yaw_inertia", kYaw},
                    {"front_cornering_stiffness", kCf},
                    {"rear_cornering_stiffness", kCr},
                    {"front_slip_offset_force", kCf * kEf},
                    {"rear_slip_offset_force", kCr * kEr}});
}

// The linear bicycle (small slip angles, cos(steer) = 1) at varying speed, without vy on the
// bus: every channel and derivative is the model's right-hand side at the sample (RK4 between
// samples), so the no-vy model's equations hold exactly.
model::ChannelSet linear_bicycle_run_without_vy() {
  const Eigen::Index n = 4000;
  const double dt = 0.01;
  const Sines steer{0.0, {0.04, 0.015}, {0.9, 2.7}, {0.0, 0.4}};
  const Sines speed{18.0, {5.0}, {0.1}, {0.0}};
  struct Forces {
    double front, rear, front_rate, rear_rate;
  };
  // The tyre forces and their rates at state s = (vy, r) with state derivative ds.
  auto forces = [&](double t, const Eigen::Vector2d& s, const Eigen::Vector2d& ds) {
    const double vx = speed.value(t), dvx = speed.derivative(t);
    const double front = s(0) + kA * s(1), rear = s(0) - kB * s(1);
    return Forces{kCf * (steer.value(t) - front / vx), -kCr * rear / vx,
                  kCf * (steer.derivative(t) - (ds(0) + kA * ds(1)) / vx + front * dvx / (vx * vx)),
                  -kCr * ((ds(0) - kB * ds(1)) / vx - rear * dvx / (vx * vx))};
  };
  auto rhs = [&](double t, const Eigen::Vector2d& s) {
    const Forces f = forces(t, s, Eigen::Vector2d::Zero());  // the forces need no rates
    return Eigen::Vector2d((f.front + f.rear) / kMass - s(1) * speed.value(t),
                           (kA * f.front - kB * f.rear) / kYaw);
  };
  model::ChannelSet set(dt, n);
  Eigen::VectorXd vx(n), dvx(n), r(n), dr(n), ay(n), day(n), st(n), dst(n);
  Eigen::Vector2d s(0.0, 0.0);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = dt * static_cast<double>(k);
    const Eigen::Vector2d ds = rhs(t, s);
    const Forces f = forces(t, s, ds);
    vx(k) = speed.value(t), dvx(k) = speed.derivative(t), r(k) = s(1), dr(k) = ds(1);
    st(k) = steer.value(t), dst(k) = steer.derivative(t);
    ay(k) = (f.front + f.rear) / kMass, day(k) = (f.front_rate + f.rear_rate) / kMass;
    const Eigen::Vector2d k1 = ds, k2 = rhs(t + dt / 2, s + dt / 2 * k1),
                          k3 = rhs(t + dt / 2, s + dt / 2 * k2), k4 = rhs(t + dt, s + dt * k3);
    s += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  set.add("vx", "m/s", vx);
  set.add("d_vx", "m/s^2", dvx);
  set.add("yaw_rate", "rad/s", r);
  set.add("d_yaw_rate", "rad/s^2", dr);
  set.add("ay", "m/s^2", ay);
  set.add("d_ay", "m/s^2/s", day);
  set.add("steer", "rad", st);
  set.add("d_steer", "rad/s", dst);
  return set;
}

// What the no-vy model identifies, from the bicycle's constants.
constexpr double kSteerPerYawAcceleration = kYaw * (kCf + kCr) / ((kA + kB) * kCf * kCr);
constexpr double kUndersteerGradient = kMass * (kB * kCr - kA * kCf) / ((kA + kB) * kCf * kCr);

TEST(LateralBicycleNoVy, KnownMassRecoversStiffnessesAndTheYawTerms) {
  const auto m =
      model::make_model("lateral_bicycle_no_vy", {{"a", kA}, {"b", kB}, {"mass", kMass}});
  expect_recovered(identify(*m, linear_bicycle_run_without_vy()),
                   {{"front_cornering_stiffness", kCf},
                    {"rear_cornering_stiffness", kCr},
                    {"steer_per_yaw_acceleration", kSteerPerYawAcceleration},
                    {"understeer_gradient", kUndersteerGradient}});
}

TEST(LateralBicycleNoVy, UnknownMassRecoversPerUnitMassStiffnesses) {
  const auto m = model::make_model("lateral_bicycle_no_vy", {{"a", kA}, {"b", kB}});
  const Identified id = identify(*m, linear_bicycle_run_without_vy());
  expect_recovered(id, {{"front_cornering_stiffness_per_mass", kCf / kMass},
                        {"rear_cornering_stiffness_per_mass", kCr / kMass},
                        {"steer_per_yaw_acceleration", kSteerPerYawAcceleration},
                        {"understeer_gradient", kUndersteerGradient}});
  // The yaw inertia per unit mass follows from the identified values (the header's identity).
  const double cf = id.value("front_cornering_stiffness_per_mass");
  const double cr = id.value("rear_cornering_stiffness_per_mass");
  EXPECT_NEAR(id.value("steer_per_yaw_acceleration") * (kA + kB) * cf * cr / (cf + cr),
              kYaw / kMass, 1e-6 * kYaw / kMass);
}

TEST(Kinematic, LongitudinalScaleOffsetAndGradeGain) {
  const Eigen::Index n = 2000;
  const Eigen::VectorXd t = time_grid(0.01, n);
  const Eigen::VectorXd dvx = Sines{0.2, {1.5, 0.4}, {0.5, 2.0}, {0.0, 1.0}}.values(t);
  const Eigen::VectorXd grade = Sines{0.01, {0.04}, {0.07}, {0.0}}.values(t);
  model::ChannelSet set(0.01, n);
  set.add("d_vx", "m/s^2", dvx);
  set.add("road_grade", "rad", grade);
  // A 2 % gain error, a 0.15 m/s^2 offset and the grade seen through the gain.
  set.add("ax", "m/s^2",
          1.02 * (dvx + kG * grade.array().sin().matrix()) + Eigen::VectorXd::Constant(n, 0.15));
  const auto m = model::make_model("kinematic_longitudinal", {});
  expect_recovered(identify(*m, set, {"road_grade"}),
                   {{"sensor_scale", 1.02}, {"sensor_offset", 0.15}, {"grade_gain", 1.02}});
}

TEST(Kinematic, LateralScaleOffsetAndBank) {
  const Eigen::Index n = 2000;
  const Eigen::VectorXd t = time_grid(0.01, n);
  const Eigen::VectorXd dvy = Sines{0.0, {0.3}, {1.1}, {0.0}}.values(t);
  const Eigen::VectorXd vx = Sines{20.0, {3.0}, {0.2}, {0.0}}.values(t);
  const Eigen::VectorXd r = Sines{0.0, {0.15}, {0.6}, {0.5}}.values(t);
  const Eigen::VectorXd bank = Sines{0.0, {0.05}, {0.05}, {0.2}}.values(t);
  model::ChannelSet set(0.01, n);
  set.add("d_vy", "m/s^2", dvy);
  set.add("vx", "m/s", vx);
  set.add("yaw_rate", "rad/s", r);
  set.add("road_bank", "rad", bank);
  const Eigen::VectorXd kin = dvy + r.cwiseProduct(vx);
  set.add("ay", "m/s^2",
          0.97 * (kin + kG * bank.array().sin().matrix()) - Eigen::VectorXd::Constant(n, 0.05));
  const auto m = model::make_model("kinematic_lateral", {});
  expect_recovered(identify(*m, set, {"road_bank"}),
                   {{"sensor_scale", 0.97}, {"sensor_offset", -0.05}, {"bank_gain", 0.97}});
}

// Body truth at C: venture §6.0 (Peugeot 406, inertia and first moments at the IMU point C;
// MY and the products set to small non-zero values so that every column is tested).
const std::map<std::string, double> kBodyTruth{
    {"XX", 622.15}, {"XY", -13.0}, {"XZ", 44.12},     {"YY", 5898.1},  {"YZ", -7.6},
    {"ZZ", 6198.93}, {"MX", 2421.14}, {"MY", 3.0}, {"MZ", 15.085}, {"M", 1508.5}};

// Newton-Euler of a rigid body written independently of BodyModel::regressor (from the CG,
// with Huygens), for the measured side.
Eigen::Matrix<double, 6, 1> body_wrench(const Eigen::Vector3d& a, const Eigen::Vector3d& w,
                                        const Eigen::Vector3d& dw) {
  const auto& x = kBodyTruth;
  Eigen::Matrix3d j;  // at C
  j << x.at("XX"), x.at("XY"), x.at("XZ"), x.at("XY"), x.at("YY"), x.at("YZ"), x.at("XZ"),
      x.at("YZ"), x.at("ZZ");
  const Eigen::Vector3d ms(x.at("MX"), x.at("MY"), x.at("MZ"));
  const double m = x.at("M");
  const Eigen::Vector3d c = ms / m;  // CG from C
  const Eigen::Vector3d a_g = a + dw.cross(c) + w.cross(w.cross(c));  // specific force at G
  Eigen::Matrix<double, 6, 1> out;
  out.head<3>() = m * a_g;
  const Eigen::Matrix3d c_cross = (Eigen::Matrix3d() << 0, -c.z(), c.y(), c.z(), 0, -c.x(),
                                   -c.y(), c.x(), 0).finished();
  const Eigen::Matrix3d j_g = j + m * c_cross * c_cross;  // Huygens: J_C = J_G - m c~ c~
  out.tail<3>() = j_g * dw + w.cross(j_g * w) + c.cross(out.head<3>());
  return out;
}

TEST(Body, SixByTenRecoversMassFirstMomentsAndInertiaTensorWithGroupWeights) {
  const Eigen::Index n = 3000;
  const Eigen::VectorXd t = time_grid(0.01, n);
  const std::array<Sines, 3> acc{Sines{0.0, {2.0, 0.5}, {0.4, 1.9}, {0.0, 0.3}},
                                 Sines{0.0, {4.0, 1.0}, {0.7, 2.3}, {1.0, 0.0}},
                                 Sines{kG, {0.8, 0.3}, {1.3, 3.1}, {0.2, 0.9}}};
  const std::array<Sines, 3> rate{Sines{0.0, {0.08, 0.03}, {1.1, 2.9}, {0.0, 0.5}},
                                  Sines{0.0, {0.05, 0.02}, {0.9, 3.3}, {0.7, 0.1}},
                                  Sines{0.0, {0.3, 0.1}, {0.5, 1.7}, {0.2, 0.8}}};
  const std::array<Eigen::Vector3d, 4> hub{Eigen::Vector3d(2.7, 0.75, 0.0),
                                           Eigen::Vector3d(2.7, -0.75, 0.0),
                                           Eigen::Vector3d(0.0, 0.74, 0.0),
                                           Eigen::Vector3d(0.0, -0.74, 0.0)};
  const std::array<const char*, 4> corner{"fl", "fr", "rl", "rr"};
  const std::array<const char*, 6> part{"fx", "fy", "fz", "mx", "my", "mz"};
  std::array<Eigen::VectorXd, 24> hubs;
  for (auto& h : hubs) h.resize(n);
  Eigen::MatrixXd motion(n, 9);
  for (Eigen::Index k = 0; k < n; ++k) {
    Eigen::Vector3d a, w, dw;
    for (int i = 0; i < 3; ++i) {
      a(i) = acc[static_cast<std::size_t>(i)].value(t(k));
      w(i) = rate[static_cast<std::size_t>(i)].value(t(k));
      dw(i) = rate[static_cast<std::size_t>(i)].derivative(t(k));
    }
    motion.row(k) << a.transpose(), w.transpose(), dw.transpose();
    // Three hubs carry arbitrary smooth wrenches; the fourth closes the balance at C.
    Eigen::Matrix<double, 6, 1> rest = body_wrench(a, w, dw);
    for (std::size_t c = 0; c < 3; ++c) {
      Eigen::Matrix<double, 6, 1> h;
      for (int j = 0; j < 6; ++j)
        h(j) = (j < 3 ? 3000.0 : 50.0) * std::sin((0.3 + 0.1 * j + 0.05 * c) * t(k) + j);
      rest.head<3>() -= h.head<3>();
      rest.tail<3>() -= h.tail<3>() + hub[c].cross(Eigen::Vector3d(h.head<3>()));
      for (std::size_t j = 0; j < 6; ++j) hubs[6 * c + j](k) = h(static_cast<Eigen::Index>(j));
    }
    const Eigen::Vector3d f4 = rest.head<3>();
    const Eigen::Vector3d m4 = rest.tail<3>() - hub[3].cross(f4);
    for (std::size_t j = 0; j < 3; ++j) {
      hubs[18 + j](k) = f4(static_cast<Eigen::Index>(j));
      hubs[21 + j](k) = m4(static_cast<Eigen::Index>(j));
    }
  }
  model::ChannelSet set(0.01, n);
  const std::array<const char*, 9> names{"ax", "ay", "az", "roll_rate", "pitch_rate",
                                         "yaw_rate", "d_roll_rate", "d_pitch_rate", "d_yaw_rate"};
  for (std::size_t i = 0; i < 9; ++i)
    set.add(names[i], i < 3 ? "m/s^2" : (i < 6 ? "rad/s" : "rad/s^2"),
            motion.col(static_cast<Eigen::Index>(i)));
  model::Constants constants;
  for (std::size_t c = 0; c < 4; ++c) {
    for (std::size_t j = 0; j < 6; ++j)
      set.add(std::string("hub_") + part[j] + "_" + corner[c], j < 3 ? "N" : "N m", hubs[6 * c + j]);
    constants[std::string("hub_x_") + corner[c]] = hub[c].x();
    constants[std::string("hub_y_") + corner[c]] = hub[c].y();
    constants[std::string("hub_z_") + corner[c]] = hub[c].z();
  }
  const auto m = model::make_model("body", constants);
  expect_recovered(identify(*m, set), kBodyTruth);

  // DYCARO's weighted groups give the same exact answer.
  ls::EquationGroups groups(10, m->groups());
  const auto rows = m->rows(set);
  for (std::size_t g = 0; g < rows.size(); ++g) groups.fold(g, rows[g].W, rows[g].y);
  const ls::WeightedEstimate we = groups.estimate();
  for (std::size_t j = 0; j < 10; ++j) {
    const std::string name = m->parameters()[j].name;
    EXPECT_LT(relative_error(we.estimate.value(static_cast<Eigen::Index>(j)), kBodyTruth.at(name)),
              1e-6)
        << name;
  }
}

TEST(Body, RegressorMatchesVentureTableRowByRow) {
  // Spot checks against the explicit table of venture §2.4 (derived there with sympy).
  const Eigen::Vector3d a(0.3, -1.2, 9.7), w(0.11, -0.07, 0.23), dw(0.5, 0.9, -0.4);
  const auto d = model::BodyModel::regressor(a, w, dw);
  EXPECT_DOUBLE_EQ(d(0, 6), -(w.y() * w.y() + w.z() * w.z()));   // Fx, MX
  EXPECT_DOUBLE_EQ(d(0, 7), w.x() * w.y() - dw.z());             // Fx, MY
  EXPECT_DOUBLE_EQ(d(1, 8), w.y() * w.z() - dw.x());             // Fy, MZ
  EXPECT_DOUBLE_EQ(d(3, 1), dw.y() - w.x() * w.z());             // Mx, XY
  EXPECT_DOUBLE_EQ(d(3, 4), w.y() * w.y() - w.z() * w.z());      // Mx, YZ
  EXPECT_DOUBLE_EQ(d(3, 8), -a.y());                             // Mx, MZ: the CG height
  EXPECT_DOUBLE_EQ(d(4, 2), w.z() * w.z() - w.x() * w.x());      // My, XZ
  EXPECT_DOUBLE_EQ(d(5, 1), w.x() * w.x() - w.y() * w.y());      // Mz, XY
  EXPECT_DOUBLE_EQ(d(5, 6), a.y());                              // Mz, MX
  EXPECT_DOUBLE_EQ(d(2, 9), a.z());                              // Fz, M
}

}  // namespace
}  // namespace dynid::test
