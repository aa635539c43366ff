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

/// The SIMEX correction on `table` (made by table_of, apply_iv applied first with `iv`, null when
/// there is no IV fit). Where the table is still least squares' and SIMEX corrected the rows (some
/// channel's noise reaches them), every identified parameter gets SIMEX's value and std, with the
/// least-squares ones it replaces beside it; statuses are classified again, and the estimator is
/// kSimex when any row changed. Why every one, even where the correction is within its own
/// uncertainty: the fold's table std counts every decimated row as independent, and SIMEX's std
/// (least squares' HAC std and the correction's own uncertainty) is the one that covers the error
/// (docs/ACCURACY.md). Where IV replaced least squares (the bias test has
/// seen the bias in the data), SIMEX takes IV's rows only when Hausman's comparison of the two
/// says its noise model holds (residual::compare_simex_with_iv), and the bias test's line gets
/// that comparison's statement either way (docs/ACCURACY.md). A fit of other columns is not
/// applied.
void apply_simex(dds::EstimateTable& table, const std::vector<model::ParameterInfo>& parameters,
                 const ls::WeightedEstimate& estimate, const residual::SimexFit& simex,
                 const residual::IvFit* iv = nullptr);

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
