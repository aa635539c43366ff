#include "declared_fit.hpp"

#include "dynid/model/registry.hpp"
#include "product_path.hpp"

namespace dynid::benchcar {

residual::ModelFit declared_fit(const car::VehicleProfile& profile, const std::string& model,
                                const ingest::RecordedRun& run,
                                const std::vector<ingest::PreprocessedSegment>& segments) {
  const ingest::ModelSpec spec = model_spec(profile, model);
  const auto m = model::make_model(spec.model, spec.constants);
  residual::FitOptions options;
  options.series = false;  // the parameters only: the series and spectra cost time
  return residual::fit_model(*m, spec.effects, segments, run.announcement.sample_rate_hz,
                             run.announcement.preprocessing.odmf, options);
}

residual::ModelFit declared_fit(const car::VehicleProfile& profile, const std::string& model,
                                const ingest::RecordedRun& run) {
  return declared_fit(profile, model, run, ingest::preprocess_offline(run));
}

residual::ModelParameters declared_hac(const car::VehicleProfile& profile, const std::string& model,
                                       const ingest::RecordedRun& run,
                                       const std::vector<ingest::PreprocessedSegment>& segments) {
  const ingest::ModelSpec spec = model_spec(profile, model);
  const auto m = model::make_model(spec.model, spec.constants);
  return residual::hac_parameters(*m, spec.effects, segments, run.announcement.sample_rate_hz,
                                  run.announcement.preprocessing.odmf);
}

residual::ModelParameters declared_compared(
    const car::VehicleProfile& profile, const std::string& model, const ingest::RecordedRun& run,
    const std::vector<ingest::PreprocessedSegment>& segments) {
  const ingest::ModelSpec spec = model_spec(profile, model);
  const auto m = model::make_model(spec.model, spec.constants);
  return residual::compared_parameters(*m, spec.effects, segments, run.announcement);
}

residual::IvFit declared_iv(const car::VehicleProfile& profile, const std::string& model,
                            const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments) {
  const ingest::ModelSpec spec = model_spec(profile, model);
  const auto m = model::make_model(spec.model, spec.constants);
  residual::IvOptions options;
  options.preprocessing = run.announcement.preprocessing;
  return residual::iv_fit(*m, spec.effects, segments, run.announcement.sample_rate_hz,
                          run.announcement.preprocessing.odmf, options);
}

}  // namespace dynid::benchcar
