#include "dynid/residual/cross_validation.hpp"

#include <cmath>
#include <string>

#include "dynid/error.hpp"

namespace dynid::residual {

void CrossValidation::validate() const {
  if (folds < 2) throw InputError("cross-validation: folds = " + std::to_string(folds) + ", at least 2");
  if (!(block_seconds > 0.0) || !std::isfinite(block_seconds))
    throw InputError("cross-validation: block_seconds = " + std::to_string(block_seconds) +
                     " is not positive");
}

int CrossValidation::fold_of(double t) const {
  const auto block = static_cast<long long>(std::floor(t / block_seconds));
  const long long f = block % folds;
  return static_cast<int>(f < 0 ? f + folds : f);
}

}  // namespace dynid::residual
