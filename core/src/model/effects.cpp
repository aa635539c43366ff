#include "dynid/model/effects.hpp"

#include <array>
#include <cmath>

#include "dictionary.hpp"
#include "dynid/error.hpp"

namespace dynid::model {
namespace {

struct Op {
  const char* token;
  const char* description;
  Eigen::Index back;     // samples needed before k
  Eigen::Index forward;  // samples needed after k
};

constexpr std::array<Op, 8> kOps{{{"x", "x", 0, 0},
                                  {"sq", "x^2", 0, 0},
                                  {"absx", "|x| x", 0, 0},
                                  {"sgn", "sgn x", 0, 0},
                                  {"d", "dx/dt (central difference)", 1, 1},
                                  {"lag1", "x delayed by 1 sample", 1, 0},
                                  {"lag2", "x delayed by 2 samples", 2, 0},
                                  {"lag3", "x delayed by 3 samples", 3, 0}}};

struct Parsed {
  const Op* op = nullptr;
  std::string channel;
};

Parsed parse(const std::string& name) {
  const std::string prefix = effect::kDictionaryPrefix;
  if (name.rfind(prefix, 0) != 0) return {};
  const std::size_t colon = name.find(':', prefix.size());
  if (colon == std::string::npos || colon + 1 >= name.size()) return {};
  const std::string token = name.substr(prefix.size(), colon - prefix.size());
  for (const Op& op : kOps)
    if (token == op.token) return {&op, name.substr(colon + 1)};
  return {};
}

double sgn(double x) { return static_cast<double>((x > 0.0) - (x < 0.0)); }

// The dictionary value of op at sample k; the caller has checked the reach of the op.
double apply(const Op* op, const Eigen::VectorXd& x, Eigen::Index k, double period) {
  switch (op - kOps.data()) {
    case 0: return x(k);
    case 1: return x(k) * x(k);
    case 2: return std::abs(x(k)) * x(k);
    case 3: return sgn(x(k));
    case 4: return (x(k + 1) - x(k - 1)) / (2.0 * period);
    default: return x(k - op->back);  // lagL
  }
}

Effect describe(const Parsed& p, const std::string& name, const std::vector<std::string>& groups) {
  Effect e{name, std::string("dictionary: ") + p.op->description + " of " + p.channel, {},
           {p.channel}};
  for (const std::string& g : groups) {
    const std::string param = groups.size() == 1 ? name : name + "@" + g;
    e.parameters.push_back({param, "", "coefficient of " + name + " in group " + g, 0.0});
  }
  return e;
}

}  // namespace

bool is_dictionary_effect(const std::string& name) { return parse(name).op != nullptr; }

Effect dictionary_effect(const std::string& name, const std::vector<std::string>& groups) {
  const Parsed p = parse(name);
  if (p.op == nullptr)
    throw InputError("dictionary effect '" + name + "': not of the form dict:<op>:<channel>");
  return describe(p, name, groups);
}

std::vector<Effect> dictionary_effects(const ChannelSet& channels) {
  std::vector<Effect> out;
  for (const std::string& channel : channels.names())
    for (const Op& op : kOps) {
      const std::string name = std::string(effect::kDictionaryPrefix) + op.token + ":" + channel;
      out.push_back(describe({&op, channel}, name, {"model"}));
    }
  return out;
}

namespace detail {

RowModel::EffectDefinition dictionary_definition(const std::string& name,
                                                 const std::vector<std::string>& groups) {
  const Parsed p = parse(name);
  RowModel::EffectDefinition def{dictionary_effect(name, groups), {}};
  def.bind = [p](const ChannelSet& set) -> RowModel::ColumnFn {
    const Eigen::VectorXd& x = set[p.channel];
    const Op* op = p.op;
    const double period = set.sample_period();
    return [&x, &set, op, period](Eigen::Index k, std::size_t group, double* out) {
      if (k < op->back || k + op->forward >= set.samples()) return false;
      for (Eigen::Index j = k - op->back; j <= k + op->forward; ++j)
        if (!set.valid(j)) return false;
      out[group] = apply(op, x, k, period);
      return true;
    };
  };
  return def;
}

}  // namespace detail
}  // namespace dynid::model
