#include "product_path.hpp"

#include <dynid/car/candump_source.hpp>
#include <dynid/car/pipeline.hpp>

#include "dynid/error.hpp"

namespace dynid::benchcar {

const car::VehicleProfile& profile(const std::filesystem::path& path) {
  static const car::VehicleProfile p = car::load_vehicle_profile(path);
  return p;
}

ingest::ModelSpec model_spec(const car::VehicleProfile& profile, const std::string& model) {
  for (const ingest::ModelSpec& m : profile.models)
    if (m.model == model) return m;
  throw InputError("the bench car's profile has no model " + model);
}

ProductRun through_product(const car::VehicleProfile& profile, const Truth& truth, const Perturbation& perturbation,
                           const BusOptions& bus, const std::string& run_name,
                           const std::filesystem::path& work_dir) {
  std::filesystem::create_directories(work_dir);
  const std::filesystem::path log = work_dir / (run_name + ".log");
  write_can_log(log, *profile.dbc, truth, perturbation, bus);
  std::vector<ingest::Chunk> chunks;
  ProductRun out;
  {
    car::CarPipeline pipeline(profile, run_name, [&](ingest::Chunk&& c) { chunks.push_back(std::move(c)); });
    car::CandumpSource source(log);
    out.progress = car::replay(source, pipeline);
  }
  std::filesystem::remove(log);
  if (out.progress.bad != 0 || out.progress.unknown_id != 0 || out.progress.rows == 0)
    throw InputError(run_name + ": replay: " + std::to_string(out.progress.bad) + " bad frames, " +
                     std::to_string(out.progress.unknown_id) + " unknown ids, " + std::to_string(out.progress.rows) + " rows");
  out.recorded = ingest::assemble_run(profile.announcement(run_name), chunks);
  return out;
}

}  // namespace dynid::benchcar
