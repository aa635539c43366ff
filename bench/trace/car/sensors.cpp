#include "sensors.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <random>

#include <dynid/can/candump.hpp>
#include <dynid/can/encoder.hpp>

#include "dynid/error.hpp"

namespace dynid::benchcar {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
constexpr double kRpm = 60.0 / (2.0 * std::numbers::pi);
constexpr double kG = 1.0 / 9.80665;

double cycle_s(const can::Database& db, const can::Message& m) {
  const auto v = can::attribute_value(db, m.attributes, "GenMsgCycleTime");
  if (v)
    if (const auto* i = std::get_if<std::int64_t>(&*v)) return static_cast<double>(*i) * 1e-3;
  return 0.1;
}

}  // namespace

const std::vector<SensorSpec>& sensor_set() {
  static const std::vector<SensorSpec> set = {
      {"vx", "LGR_Motion", {"VelLong"}, 1.0, 0.008},
      {"vy", "LGR_Motion", {"VelLat"}, 1.0, 0.008},
      {"wheel_torque", "LGR_Motion", {"WhlTrq_RL", "WhlTrq_RR"}, 1e-3, 10.0},
      {"yaw_rate", "CHS_Inertial", {"YawRateZ"}, kDeg, 0.003},
      {"ay", "CHS_Inertial", {"AccLat"}, kG, 0.05},
      {"ax", "CHS_Inertial", {"AccLong"}, kG, 0.05},
      {"steer", "STR_Angle", {"SteerWhlAng"}, kDeg * 15.2, 0.15 / (kDeg * 15.2)},
      {"engine_speed", "ENG_Data", {"EngSpd"}, kRpm, 2.0 / kRpm},
      {"engine_torque", "ENG_Data", {"EngTrqAct"}, 1.0, 2.0},
      {"gearbox_input_speed", "TRN_Status", {"InpShftSpd"}, kRpm, 3.0 / kRpm},
      {"gear", "TRN_Status", {"GearAct"}, 1.0, 0.0},
      {"gear_ratio", "TRN_Status", {"GearRatioTot"}, 1.0, 0.0},
      {"clutch_clamp_load", "CLU_Actuator", {"ClmpLoad"}, 1e-3, 20.0},
      {"clutch_engagement", "CLU_Actuator", {"ClutchPos"}, 1.0, 0.002, true},
      {"brake_pressure", "BRK_Press", {"MstCylPrs"}, 1e-3, 3000.0},
  };
  return set;
}

std::size_t write_can_log(const std::filesystem::path& path, const can::Database& dbc, const Truth& truth,
                          const Perturbation& p, const BusOptions& options) {
  std::mt19937_64 rng(options.seed * 2654435761ULL + 17);
  // The own_stream sensors' noise (a distribution of its own too: one keeps a spare draw).
  std::mt19937_64 own_rng(options.seed * 2654435761ULL + 29);
  std::normal_distribution<double> own_normal(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  // The messages in DBC order, each with its sensors.
  struct Out {
    const can::Message* message;
    double period;
    double phase;
    std::vector<const SensorSpec*> sensors;
  };
  std::vector<Out> outs;
  std::map<std::string, std::size_t> index;
  for (const SensorSpec& s : sensor_set()) {
    if (!index.count(s.message)) {
      const can::Message* m = dbc.find_message(s.message);
      if (m == nullptr) throw InputError("benchcar.dbc has no message " + s.message);
      const double period = cycle_s(dbc, *m);
      // 100 Hz messages on the grid; slower ones half a period off it (interpolated).
      outs.push_back({m, period, period > 0.0105 ? 0.005 : 0.0, {}});
      index[s.message] = outs.size() - 1;
    }
    outs[index[s.message]].sensors.push_back(&s);
  }
  std::ofstream file(path);
  if (!file) throw InputError(path.string() + ": cannot write");
  can::CandumpWriter writer(file);
  // Frames in time order: step through a 1 ms clock.
  const double end = truth.time.back();
  std::size_t frames = 0;
  std::vector<can::SignalValue> values;
  std::vector<std::string> keep;
  const double t0 = 1000.0;  // the logger's clock at the run's start
  for (long k = 0; static_cast<double>(k) * 1e-3 <= end; ++k) {
    const double t = static_cast<double>(k) * 1e-3;
    for (const Out& o : outs) {
      const long per = std::lround(o.period * 1e3);
      const long ph = std::lround(o.phase * 1e3);
      if (k < ph || (k - ph) % per != 0) continue;
      values.clear();
      for (const SensorSpec* s : o.sensors) {
        const auto delay = p.delay.find(s->channel);
        const double when = t - (delay == p.delay.end() ? 0.0 : delay->second);
        double si = truth.at(s->channel, when);
        if (s->channel == "ay" && p.imu_roll_mount != 0.0)
          si = si * std::cos(p.imu_roll_mount) + truth.at("az", when) * std::sin(p.imu_roll_mount);
        if (s->channel == "wheel_torque") si *= p.wheel_torque_scale;
        if (s->channel == "gear" || s->channel == "gear_ratio") si = truth.at(s->channel, std::floor(when * 1e3 + 0.5) * 1e-3);
        const double per_signal = si / static_cast<double>(s->signals.size());
        const double sigma = options.noise_scale * s->noise / std::sqrt(static_cast<double>(s->signals.size()));
        for (const std::string& name : s->signals) {
          const double sign = options.mirrored ? -1.0 : 1.0;
          double v =
              per_signal + (sigma > 0.0
                                ? sign * sigma * (s->own_stream ? own_normal(own_rng) : normal(rng))
                                : 0.0);
          // Toothed-wheel speed sensors read a standing shaft as exactly 0, without noise, and
          // never a negative speed (a slow shaft's noise would otherwise leave the DBC's range).
          if (s->channel == "engine_speed" || s->channel == "gearbox_input_speed")
            v = si < 1.0 ? std::max(si, 0.0) : std::max(v, 0.0);
          values.push_back({name, v * s->to_dbc});
        }
      }
      can::Frame frame;
      frame.timestamp = t0 + t;
      frame.set_interface_name("can1");
      const can::EncodeReport report = can::encode_frame(*o.message, values, frame);
      if (!report.clamped.empty()) throw InputError("benchcar: " + report.clamped.front() + " out of range at t = " + std::to_string(t));
      writer.write(frame);
      ++frames;
    }
  }
  if (!file) throw InputError(path.string() + ": write failed");
  return frames;
}

}  // namespace dynid::benchcar
