#include "dynid/residual/varying_parameter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "dynid/error.hpp"
#include "dynid/input/number.hpp"

namespace dynid::residual {
namespace {

constexpr const char* kDrift = "drift:";
constexpr const char* kStep = "step:";
constexpr const char* kDepends = "depends:";

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

Eigen::Index column_of(const model::Model& model, const std::string& name, const std::string& effect) {
  const std::vector<model::ParameterInfo> parameters = model.parameters();
  for (std::size_t j = 0; j < parameters.size(); ++j)
    if (parameters[j].name == name) return static_cast<Eigen::Index>(j);
  throw InputError("effect '" + effect + "': model '" + model.name() + "' has no parameter '" + name + "'");
}

// The cumulative quantities: name, unit, the channels the rate reads, and the rate.
struct Quantity {
  const char* name;
  const char* unit;
  std::vector<std::string> channels;
  double (*rate)(const std::vector<const Eigen::VectorXd*>& x, Eigen::Index k);
};

const std::vector<Quantity>& quantities() {
  static const std::vector<Quantity> all = {
      {"distance", "m", {"vx"}, [](const std::vector<const Eigen::VectorXd*>& x, Eigen::Index k) {
         return std::abs((*x[0])(k));
       }},
      {"clutch_energy", "J", {"engine_torque", "engine_speed", "gearbox_input_speed"},
       [](const std::vector<const Eigen::VectorXd*>& x, Eigen::Index k) {
         return std::abs((*x[0])(k) * ((*x[1])(k) - (*x[2])(k)));
       }}};
  return all;
}

const Quantity* find_quantity(const std::string& name) {
  for (const Quantity& q : quantities())
    if (name == q.name) return &q;
  return nullptr;
}

bool known_quantity(const std::string& name) { return find_quantity(name) != nullptr; }

std::string seconds(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", t);
  return buf;
}

}  // namespace

bool is_varying_effect(const std::string& name) {
  return starts_with(name, kDrift) || starts_with(name, kStep) || starts_with(name, kDepends);
}

VaryingParameter parse_varying_effect(const std::string& name, const model::Model& model) {
  VaryingParameter v;
  if (starts_with(name, kDrift)) {
    const std::string rest = name.substr(std::string(kDrift).size());
    const auto tilde = rest.find('~');
    v.parameter = rest.substr(0, tilde);
    v.column = column_of(model, v.parameter, name);
    if (tilde == std::string::npos) return v;
    v.kind = VaryingParameter::Kind::kCumulative;
    v.channel = rest.substr(tilde + 1);
    if (!known_quantity(v.channel))
      throw InputError("effect '" + name + "': '" + v.channel + "' is no cumulative quantity (distance, clutch_energy)");
    return v;
  }
  if (starts_with(name, kDepends)) {
    const std::string rest = name.substr(std::string(kDepends).size());
    const auto tilde = rest.find('~');
    if (tilde == std::string::npos || tilde + 1 == rest.size())
      throw InputError("effect '" + name + "': expected depends:<parameter>~<channel>");
    v.kind = VaryingParameter::Kind::kChannel;
    v.parameter = rest.substr(0, tilde);
    v.channel = rest.substr(tilde + 1);
    v.column = column_of(model, v.parameter, name);
    return v;
  }
  if (!starts_with(name, kStep))
    throw InputError("effect '" + name + "' is not drift:<parameter>, step:<parameter>@<t>s nor depends:<parameter>~<channel>");
  const std::string rest = name.substr(std::string(kStep).size());
  const auto at = rest.rfind('@');
  if (at == std::string::npos || rest.size() < at + 3 || rest.back() != 's')
    throw InputError("effect '" + name + "': expected step:<parameter>@<seconds>s");
  v.kind = VaryingParameter::Kind::kStep;
  v.parameter = rest.substr(0, at);
  v.column = column_of(model, v.parameter, name);
  const std::string time = rest.substr(at + 1, rest.size() - at - 2);
  const std::optional<double> t0 = input::parse_finite(time);
  if (!t0) throw InputError("effect '" + name + "': '" + time + "' is not a time in seconds");
  v.step_time_s = *t0;
  return v;
}

std::vector<std::string> cumulative_quantities(const std::vector<std::string>& channels) {
  std::vector<std::string> out;
  for (const Quantity& q : quantities())
    if (std::all_of(q.channels.begin(), q.channels.end(), [&](const std::string& c) {
          return std::find(channels.begin(), channels.end(), c) != channels.end();
        }))
      out.emplace_back(q.name);
  return out;
}

Eigen::VectorXd cumulative_rate(const std::string& quantity, const model::ChannelSet& channels) {
  const Quantity* q = find_quantity(quantity);
  if (q == nullptr) throw InputError("cumulative quantity '" + quantity + "' is unknown (distance, clutch_energy)");
  std::vector<const Eigen::VectorXd*> x;
  for (const std::string& c : q->channels) {
    if (!channels.has(c))
      throw InputError("cumulative quantity '" + quantity + "': the run has no channel '" + c + "'");
    x.push_back(&channels[c]);
  }
  Eigen::VectorXd rate = Eigen::VectorXd::Zero(channels.samples());
  for (Eigen::Index k = 0; k < rate.size(); ++k) {
    const double r = channels.valid(k) ? q->rate(x, k) : 0.0;
    rate(k) = std::isfinite(r) ? r : 0.0;
  }
  return rate;
}

model::ParameterInfo varying_parameter_info(const VaryingParameter& v, const model::Model& model) {
  const model::ParameterInfo p = model.parameters()[static_cast<std::size_t>(v.column)];
  if (v.kind == VaryingParameter::Kind::kCumulative) {
    const std::string unit = find_quantity(v.channel)->unit;
    return {p.name + "_per_" + v.channel, p.unit + " per " + unit,
            "change of " + p.name + " per " + unit + " of " + v.channel + " accumulated over the run (the parameter is its value at the run's mean " +
                v.channel + ")",
            std::nullopt};
  }
  if (v.kind == VaryingParameter::Kind::kDrift)
    return {p.name + "_drift", p.unit + "/s", "rate of change of " + p.name + " over the run (the parameter is its mid-run value)",
            std::nullopt};
  if (v.kind == VaryingParameter::Kind::kChannel)
    return {p.name + "_per_" + v.channel, p.unit + " per unit of " + v.channel,
            "change of " + p.name + " per unit of " + v.channel + " (the parameter is its value at " + v.channel +
                "'s run mean)",
            std::nullopt};
  return {p.name + "_step@" + seconds(v.step_time_s) + "s", p.unit,
          "change of " + p.name + " at " + seconds(v.step_time_s) + " s (the parameter is its value before)",
          std::nullopt};
}

std::vector<std::string> varying_candidates(const model::Model& model, double t_first, double t_last,
                                            double block_s, const std::vector<std::string>& channels,
                                            const std::vector<std::string>& quantities) {
  std::vector<std::string> out;
  // Block boundaries from the second block's end to one block before the last sample.
  const double first = (std::floor(t_first / block_s) + 2.0) * block_s;
  int boundaries = 0;
  while (first + boundaries * block_s <= t_last - block_s) ++boundaries;
  const int every = std::max(1, (boundaries + kMaxStepTimes - 1) / kMaxStepTimes);
  for (const model::ParameterInfo& p : model.parameters()) {
    out.push_back(kDrift + p.name);
    for (const std::string& q : quantities) out.push_back(kDrift + p.name + "~" + q);
    for (const std::string& c : channels) out.push_back(kDepends + p.name + "~" + c);
    for (int b = 0; b < boundaries; b += every)
      out.push_back(kStep + p.name + "@" + seconds(first + b * block_s) + "s");
  }
  return out;
}

double varying_column(const VaryingParameter& v, double w, double t, double t_mid, double centred) {
  if (v.kind == VaryingParameter::Kind::kDrift) return w * (t - t_mid);
  if (v.kind == VaryingParameter::Kind::kChannel || v.kind == VaryingParameter::Kind::kCumulative) return w * centred;
  return t >= v.step_time_s ? w : 0.0;
}

}  // namespace dynid::residual
