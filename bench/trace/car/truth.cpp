#include "truth.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/error.hpp"

namespace dynid::benchcar {

double Truth::at(const std::string& name, double t) const {
  const auto it = channels.find(name);
  if (it == channels.end()) throw InputError("benchcar truth has no channel " + name);
  const std::vector<double>& x = it->second;
  const double pos = std::clamp((t - time.front()) * rate_hz, 0.0, static_cast<double>(x.size() - 1));
  const auto i = static_cast<std::size_t>(std::floor(pos));
  if (i + 1 >= x.size()) return x.back();
  const double f = pos - static_cast<double>(i);
  return x[i] + f * (x[i + 1] - x[i]);
}

}  // namespace dynid::benchcar
