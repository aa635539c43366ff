#include "dynid/sim/scenario.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <toml++/toml.h>

#include "dynid/error.hpp"
#include "dynid/sim/channels.hpp"

namespace dynid::sim {
namespace {

class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    throw InputError(source_ + ": " + key + ": " + why);
  }

  double number(const toml::node& n, const std::string& key) const {
    if (auto v = n.value<double>(); v && std::isfinite(*v)) return *v;
    fail(key, "expected a finite number");
  }
  bool boolean(const toml::node& n, const std::string& key) const {
    if (auto v = n.value<bool>()) return *v;
    fail(key, "expected true or false");
  }
  std::string string(const toml::node& n, const std::string& key) const {
    if (auto v = n.value<std::string>()) return *v;
    fail(key, "expected a string");
  }
  std::int64_t integer(const toml::node& n, const std::string& key) const {
    if (auto v = n.value<std::int64_t>()) return *v;
    fail(key, "expected an integer");
  }
  const toml::table& table(const toml::node& n, const std::string& key) const {
    if (const auto* t = n.as_table()) return *t;
    fail(key, "expected a table");
  }

  Profile profile(const toml::node& n, const std::string& key) const {
    const auto* arr = n.as_array();
    if (arr == nullptr) fail(key, "expected an array of [distance, value] pairs");
    std::vector<std::pair<double, double>> points;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const auto* pair = (*arr)[i].as_array();
      const std::string where = key + "[" + std::to_string(i) + "]";
      if (pair == nullptr || pair->size() != 2) fail(where, "expected [distance, value]");
      points.emplace_back(number((*pair)[0], where), number((*pair)[1], where));
    }
    try {
      return Profile(std::move(points));
    } catch (const InputError& e) {
      fail(key, e.what());
    }
  }

 private:
  std::string source_;
};

void read_run(const Reader& r, const toml::table& t, Scenario& s) {
  for (const auto& [k, node] : t) {
    const std::string key = "run." + std::string(k.str());
    const std::string_view name = k.str();
    if (name == "name") s.name = r.string(node, key);
    else if (name == "duration") s.duration = r.number(node, key);
    else if (name == "internal_rate") s.internal_rate = r.number(node, key);
    else if (name == "output_rate") s.output_rate = r.number(node, key);
    else if (name == "seed") s.seed = static_cast<std::uint64_t>(r.integer(node, key));
    else if (name == "start_timestamp") s.start_timestamp = r.number(node, key);
    else if (name == "interface") s.interface_name = r.string(node, key);
    else if (name == "noise_scale") s.noise_scale = r.number(node, key);
    else r.fail(key, "unknown key");
  }
}

void read_manoeuvre(const Reader& r, const toml::table& t, ManoeuvreSpec& m) {
  const std::vector<std::pair<std::string, double*>> numbers{
      {"speed", &m.speed}, {"start_time", &m.start_time}, {"amplitude", &m.amplitude},
      {"amplitude_end", &m.amplitude_end}, {"frequency_start", &m.frequency_start},
      {"frequency_end", &m.frequency_end}, {"sweep_time", &m.sweep_time}, {"ramp_time", &m.ramp_time},
      {"steer_rate", &m.steer_rate}, {"max_steer", &m.max_steer}, {"drive_torque", &m.drive_torque},
      {"torque_variation", &m.torque_variation}, {"shift_speed", &m.shift_speed},
      {"shift_time", &m.shift_time}, {"launch_engine_speed", &m.launch_engine_speed},
      {"engagement_time", &m.engagement_time}, {"rev_limit", &m.rev_limit},
      {"stop_pressure", &m.stop_pressure}, {"wait_time", &m.wait_time}, {"slip_min", &m.slip_min},
      {"slip_max", &m.slip_max}, {"slip_period", &m.slip_period},
      {"drag_pressure", &m.drag_pressure}, {"drag_period", &m.drag_period}};
  for (const auto& [k, node] : t) {
    const std::string name(k.str());
    const std::string key = "manoeuvre." + name;
    if (name == "type") {
      try {
        m.type = parse_manoeuvre_type(r.string(node, key));
      } catch (const InputError& e) {
        r.fail(key, e.what());
      }
      continue;
    }
    if (name == "gear") {
      m.gear = static_cast<int>(r.integer(node, key));
      continue;
    }
    bool found = false;
    for (const auto& [n, p] : numbers)
      if (n == name) { *p = r.number(node, key); found = true; }
    if (!found) r.fail(key, "unknown key");
  }
}

void read_effects(const Reader& r, const toml::table& t, Effects& e) {
  auto named = named_effects(e);
  for (const auto& [k, node] : t) {
    const std::string name(k.str());
    bool found = false;
    for (const auto& [n, p] : named)
      if (n == name) { *p = r.boolean(node, "effects." + name); found = true; }
    if (!found) r.fail("effects." + name, "unknown effect");
  }
}

void read_parameters(const Reader& r, const std::string& prefix, const toml::table& t, CarParameters& car) {
  auto named = named_parameters(car);
  for (const auto& [k, node] : t) {
    const std::string key = prefix + "." + std::string(k.str());
    if (key == "driveline.gear_ratios") {
      const auto* arr = node.as_array();
      if (arr == nullptr || arr->empty()) r.fail(key, "expected a non-empty array of ratios");
      car.driveline.gear_ratios.clear();
      for (const auto& x : *arr) car.driveline.gear_ratios.push_back(r.number(x, key));
      continue;
    }
    bool found = false;
    for (const auto& [n, p] : named)
      if (n == key) { *p = r.number(node, key); found = true; }
    if (!found) r.fail(key, "unknown parameter");
  }
}

void check(const Reader& r, const Scenario& s) {
  if (!(s.duration > 0.0)) r.fail("run.duration", "must be > 0");
  if (!(s.internal_rate >= 100.0)) r.fail("run.internal_rate", "must be >= 100 Hz");
  const double ratio = s.internal_rate / s.output_rate;
  if (!(s.output_rate > 0.0) || std::abs(ratio - std::round(ratio)) > 1e-9)
    r.fail("run.output_rate", "must divide the internal rate");
  if (!(s.noise_scale >= 0.0)) r.fail("run.noise_scale", "must be >= 0");
  const auto& m = s.manoeuvre;
  if (m.gear < 0 || m.gear > s.car.driveline.gear_count()) r.fail("manoeuvre.gear", "no such gear");
  if (m.type != ManoeuvreType::Launch && m.type != ManoeuvreType::CoastDown && m.gear == 0)
    r.fail("manoeuvre.gear", "this manoeuvre drives in gear: 1..n");
  if (!(m.speed >= 0.0)) r.fail("manoeuvre.speed", "must be >= 0");
  if (!(m.sweep_time > 0.0)) r.fail("manoeuvre.sweep_time", "must be > 0");
  if (!(m.ramp_time > 0.0)) r.fail("manoeuvre.ramp_time", "must be > 0");
  if (!(m.engagement_time > 0.0)) r.fail("manoeuvre.engagement_time", "must be > 0");
  if (!(m.wait_time > 0.0)) r.fail("manoeuvre.wait_time", "must be > 0");
  if (!(m.shift_time > 0.0)) r.fail("manoeuvre.shift_time", "must be > 0");
  if (!(m.slip_min > 0.0)) r.fail("manoeuvre.slip_min", "must be > 0");
  if (!(m.slip_max >= m.slip_min)) r.fail("manoeuvre.slip_max", "must be >= slip_min");
  if (!(m.slip_period > 0.0)) r.fail("manoeuvre.slip_period", "must be > 0");
  if (!(m.drag_pressure >= 0.0)) r.fail("manoeuvre.drag_pressure", "must be >= 0");
  if (!(m.drag_period > 0.0)) r.fail("manoeuvre.drag_period", "must be > 0");
  const auto& v = s.car.vehicle;
  if (!(v.mass > 2.0 * (v.unsprung_mass_front + v.unsprung_mass_rear)))
    r.fail("vehicle.mass", "must exceed the unsprung masses");
  for (double x : {v.yaw_inertia, v.roll_inertia, v.pitch_inertia, v.wheel_radius, v.tyre_vertical_stiffness,
                   v.cornering_stiffness_front, v.cornering_stiffness_rear, v.unsprung_mass_front,
                   v.unsprung_mass_rear, s.car.driveline.engine_inertia, s.car.driveline.gearbox_input_inertia,
                   s.car.driveline.clutch_stribeck_speed})
    if (!(x > 0.0)) r.fail("vehicle/driveline", "masses, inertias, stiffnesses and radii must be > 0");
}

}  // namespace

Scenario parse_scenario(std::string_view text, std::string_view source_name) {
  const Reader r{std::string(source_name)};
  toml::table root;
  try {
    root = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    std::ostringstream where;
    where << e.source().begin;
    r.fail(where.str(), std::string(e.description()));
  }
  Scenario s;
  for (const auto& [k, node] : root) {
    const std::string name(k.str());
    const auto& t = r.table(node, name);
    if (name == "run") read_run(r, t, s);
    else if (name == "manoeuvre") read_manoeuvre(r, t, s.manoeuvre);
    else if (name == "effects") read_effects(r, t, s.effects);
    else if (name == "vehicle" || name == "driveline") read_parameters(r, name, t, s.car);
    else if (name == "road") {
      for (const auto& [rk, rn] : t) {
        const std::string key = "road." + std::string(rk.str());
        if (rk.str() == "grade") s.road.grade = r.profile(rn, key);
        else if (rk.str() == "bank") s.road.bank = r.profile(rn, key);
        else r.fail(key, "unknown key (grade, bank)");
      }
    } else if (name == "sensor_gain") {
      for (const auto& [ck, cn] : t) {
        const std::string channel(ck.str());
        const std::string key = "sensor_gain." + channel;
        try {
          channel_index(channel);
        } catch (const InputError& e) {
          r.fail(key, e.what());
        }
        const double gain = r.number(cn, key);
        if (!(gain > 0.0)) r.fail(key, "must be > 0");
        s.sensor_gains[channel] = gain;
      }
    } else {
      r.fail(name, "unknown table (run, manoeuvre, effects, road, vehicle, driveline, sensor_gain)");
    }
  }
  check(r, s);
  return s;
}

Scenario load_scenario(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the scenario file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scenario(text.str(), path.string());
}

}  // namespace dynid::sim
