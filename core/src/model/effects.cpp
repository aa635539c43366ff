#include "dynid/model/effects.hpp"

#include <array>
#include <cmath>

#include "dictionary.hpp"
#include "dynid/error.hpp"
#include "dynid/signal/derivative.hpp"

namespace dynid::model {
namespace {

struct Op {
  const char* token;
  const char* description;
  Eigen::Index back;     // samples needed before k
  Eigen::Index forward;  // samples needed after k
};

constexpr std::array<Op, 9> kOps{{{"x", "x", 0, 0},
                                  {"sq", "x^2", 0, 0},
                                  {"absx", "|x| x", 0, 0},
                                  {"sgn", "sgn x", 0, 0},
                                  {"d", "dx/dt (the preprocessing's five-point central difference)", 2, 2},
                                  {"lag1", "x delayed by 1 sample", 1, 0},
                                  {"lag2", "x delayed by 2 samples", 2, 0},
                                  {"lag3", "x delayed by 3 samples", 3, 0},
                                  {"prod", "product", 0, 0}}};
constexpr const char* kProduct = "prod";
constexpr char kProductSeparator = '*';

struct Parsed {
  const Op* op = nullptr;
  std::string channel;
  std::string second;  ///< the other factor of a product; empty for the other ops
  bool product() const { return !second.empty(); }
};

// "a*b" of dict:prod:a*b as its two factors; nullopt unless both are named.
Parsed parse_product(const Op* op, const std::string& factors) {
  const std::size_t star = factors.find(kProductSeparator);
  if (star == std::string::npos || star == 0 || star + 1 >= factors.size() ||
      factors.find(kProductSeparator, star + 1) != std::string::npos)
    return {};
  return {op, factors.substr(0, star), factors.substr(star + 1)};
}

Parsed parse(const std::string& name) {
  const std::string prefix = effect::kDictionaryPrefix;
  if (name.rfind(prefix, 0) != 0) return {};
  const std::size_t colon = name.find(':', prefix.size());
  if (colon == std::string::npos || colon + 1 >= name.size()) return {};
  const std::string token = name.substr(prefix.size(), colon - prefix.size());
  for (const Op& op : kOps) {
    if (token != op.token) continue;
    if (token == kProduct) return parse_product(&op, name.substr(colon + 1));
    return {&op, name.substr(colon + 1), {}};
  }
  return {};
}

double sgn(double x) { return static_cast<double>((x > 0.0) - (x < 0.0)); }

// The dictionary value of op at sample k (y: a product's second factor); the caller has checked
// the reach of the op.
double apply(const Op* op, const Eigen::VectorXd& x, const Eigen::VectorXd* y, Eigen::Index k, double period) {
  switch (op - kOps.data()) {
    case 0: return x(k);
    case 1: return x(k) * x(k);
    case 2: return std::abs(x(k)) * x(k);
    case 3: return sgn(x(k));
    case 4: return signal::inside_derivative(x, k, period);  // as d_<channel>, so the same column
    case 8: return x(k) * (*y)(k);
    default: return x(k - op->back);  // lagL
  }
}

Effect describe(const Parsed& p, const std::string& name, const std::vector<std::string>& groups) {
  Effect e{name,
           std::string("dictionary: ") + p.op->description + " of " + p.channel + (p.product() ? " and " + p.second : ""),
           {},
           p.product() ? std::vector<std::string>{p.channel, p.second} : std::vector<std::string>{p.channel}};
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
    throw InputError("dictionary effect '" + name + "': not of the form dict:<op>:<channel> (or dict:prod:<a>*<b>)");
  return describe(p, name, groups);
}

std::vector<Effect> dictionary_effects(const ChannelSet& channels) {
  std::vector<Effect> out;
  const std::vector<std::string> names = channels.names();
  for (const std::string& channel : names)
    for (const Op& op : kOps) {
      if (op.token == std::string(kProduct)) continue;
      const std::string name = std::string(effect::kDictionaryPrefix) + op.token + ":" + channel;
      out.push_back(describe({&op, channel, {}}, name, {"model"}));
    }
  const Op* product = &kOps.back();
  for (std::size_t i = 0; i < names.size(); ++i)
    for (std::size_t j = i + 1; j < names.size(); ++j) {
      const std::string name = std::string(effect::kDictionaryPrefix) + kProduct + ":" + names[i] + kProductSeparator + names[j];
      out.push_back(describe({product, names[i], names[j]}, name, {"model"}));
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
    const Eigen::VectorXd* y = p.product() ? &set[p.second] : nullptr;
    const Op* op = p.op;
    const double period = set.sample_period();
    return [&x, y, &set, op, period](Eigen::Index k, std::size_t group, double* out) {
      if (k < op->back || k + op->forward >= set.samples()) return false;
      for (Eigen::Index j = k - op->back; j <= k + op->forward; ++j)
        if (!set.valid(j)) return false;
      out[group] = apply(op, x, y, k, period);
      return true;
    };
  };
  return def;
}

}  // namespace detail
}  // namespace dynid::model
