#include "clean_run.hpp"

#include <functional>

#include "parameters.hpp"
#include "perturbation.hpp"

namespace dynid::benchcar {

std::uint64_t run_seed(const std::string& name, std::uint64_t seed) {
  return std::hash<std::string>{}(name) ^ (seed * 0x9e3779b97f4a7c15ULL);
}

CleanRun clean_run(const car::VehicleProfile& profile, Manoeuvre manoeuvre, std::uint64_t seed, double noise_scale,
                   const std::filesystem::path& work_dir, bool mirrored_noise) {
  const CarParameters car;
  const Perturbation none;
  CleanRun r;
  r.name = std::string("clean-") + manoeuvre_name(manoeuvre) + "-" + std::to_string(seed);
  r.truth = simulate(manoeuvre, car, none, seed);
  r.product = through_product(profile, r.truth, none, {noise_scale, run_seed(r.name, seed), mirrored_noise}, r.name, work_dir);
  r.segments = ingest::preprocess_offline(r.product.recorded);
  return r;
}

}  // namespace dynid::benchcar
