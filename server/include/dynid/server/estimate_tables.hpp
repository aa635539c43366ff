#pragma once
// From a run's (or a pool's) model estimates to the tables that are published and printed.
//
// tables_of(): one EstimateTable per model that has an estimate, optionally only `model`;
// models without one (not run, no row yet) are listed in `notes` with the reason. Group rows
// and residual RMS come from each group's own statistics (unweighted).
#include <optional>
#include <string>
#include <vector>

#include "dynid/dds/estimate_table.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "dynid/report/excitation_report.hpp"
#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/simex.hpp"

namespace dynid::server {

struct EstimateTables {
  std::vector<dds::EstimateTable> tables;
  std::vector<std::string> notes;  ///< "<model>: <why there is no estimate>"
};

dds::EstimateTable table_of(const std::string& vehicle, const std::string& source,
                            const std::string& model,
                            const std::vector<model::ParameterInfo>& parameters,
                            const ls::WeightedEstimate& estimate);

/// The instrumental-variable estimate on `table` (made by table_of from `parameters` and
/// `estimate`): where iv.replaces_least_squares() (IV estimated, least squares rejected by the
/// Durbin-Wu-Hausman test) the identified parameters get IV's values and HAC standard deviations,
/// their statuses classified again on those, and the least-squares ones they replace; the test's
/// one line (IvFit::statement()) either way, with `through`, the last chunk the IV fit includes.
/// An IV fit of other columns (another effect set) is not applied: `table` is left as it is.
void apply_iv(dds::EstimateTable& table, const std::vector<model::ParameterInfo>& parameters,
              const ls::WeightedEstimate& estimate, const residual::IvFit& iv, std::uint64_t through);

/// The SIMEX correction on `table` (made by table_of, apply_iv applied first): where the table is
/// still least squares', each identified parameter whose SIMEX value has a smaller estimated
/// mean squared error than least squares' (SimexFit::improves: the correction exceeds its own
/// Monte Carlo and noise-level uncertainty) gets SIMEX's value and std, with the least-squares
/// ones it replaces beside it; statuses are classified again, and the estimator is kSimex when
/// any row changed. Why not where IV replaces least squares: the bias test has then seen the bias
/// in the data, and IV removes it with no noise model (docs/ACCURACY.md). A fit of other columns
/// is not applied.
void apply_simex(dds::EstimateTable& table, const std::vector<model::ParameterInfo>& parameters,
                 const ls::WeightedEstimate& estimate, const residual::SimexFit& simex);

EstimateTables tables_of(const std::string& vehicle, const std::string& source,
                         const std::vector<ingest::ModelEstimate>& estimates,
                         const std::optional<std::string>& model = std::nullopt);

/// The run's excitation report (report/excitation_report.hpp): its tables as tables_of() makes
/// them, each parameter with the signal that excites it (model::ParameterInfo::excited_by).
report::ExcitationReport excitation_of(const std::string& vehicle, const std::string& run,
                                       const std::vector<ingest::ModelEstimate>& estimates);

/// Text (the tables, then the notes) or JSON ({"tables":[...],"notes":[...]}).
std::string render(const EstimateTables& tables, bool json);

}  // namespace dynid::server
