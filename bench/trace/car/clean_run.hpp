#pragma once
// A clean run of the second car: one manoeuvre simulated with no effect injected (the car as its
// profile describes it), measured by its sensors with their normal noise (scaled by
// noise_scale), through the product's data path. The trace benchmark's false-alarm runs and the
// coverage benchmark's runs are these; the bus noise is seeded from the run's name and seed
// (run_seed), so that one seed gives one run in both.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "manoeuvres.hpp"
#include "product_path.hpp"
#include "truth.hpp"

namespace dynid::benchcar {

/// The bus noise's seed of the run `name` at `seed`.
std::uint64_t run_seed(const std::string& name, std::uint64_t seed);

struct CleanRun {
  std::string name;  ///< "clean-<manoeuvre>-<seed>"
  Truth truth;
  ProductRun product;
  std::vector<ingest::PreprocessedSegment> segments;  ///< ingest::preprocess_offline(product.recorded)
};

/// Simulates `manoeuvre` at `seed` with no effect and sends it through the product (can.log in
/// `work_dir`, removed after); `mirrored_noise`: the same run with every noise draw's sign
/// flipped (BusOptions::mirrored). InputError as through_product.
CleanRun clean_run(const car::VehicleProfile& profile, Manoeuvre manoeuvre, std::uint64_t seed, double noise_scale,
                   const std::filesystem::path& work_dir, bool mirrored_noise = false);

}  // namespace dynid::benchcar
