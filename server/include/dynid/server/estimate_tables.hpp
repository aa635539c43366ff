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
#include "dynid/ingest/channel_health.hpp"
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

/// The publication rule (residual/publication.hpp: least squares, IV where the Durbin-Wu-Hausman
/// test rejects it, SIMEX where it corrected the rows or where Hausman's comparison lets it stand
/// in for IV) on `table`, made by table_of from `parameters` and `estimate`; `iv` and `simex` are
/// the run's fits of the same configuration (null: not computed; a fit of other columns is
/// ignored). The replaced rows get the chosen estimator's values and std with the least-squares
/// ones beside them, and their statuses are classified again on those; the fit's figures stay
/// least squares'. Where an IV fit was given, the bias test's line (and `through`, the last chunk
/// the fits include) is set whichever estimator is published. Why SIMEX on every identified row,
/// even where the correction is within its own uncertainty: the fold's table std counts every
/// decimated row as independent, and SIMEX's std (least squares' HAC std and the correction's own
/// uncertainty) is the one that covers the error (docs/ACCURACY.md).
void apply_publication(dds::EstimateTable& table,
                       const std::vector<model::ParameterInfo>& parameters,
                       const ls::WeightedEstimate& estimate, const residual::IvFit* iv,
                       const residual::SimexFit* simex, std::uint64_t through);

EstimateTables tables_of(const std::string& vehicle, const std::string& source,
                         const std::vector<ingest::ModelEstimate>& estimates,
                         const std::optional<std::string>& model = std::nullopt);

/// Every table whose model reads a channel that is unhealthy on the run (ingest::unhealthy_reason,
/// with the announcement's spec of the model) gets `not_identified` and loses what would judge
/// it: the not-excited advice, the residual verdict and the bias test. Every finding of the run
/// is added to the notes ("channel health: <statement>").
void apply_health(EstimateTables& tables, const ingest::RunHealth& health,
                  const ingest::RunAnnouncement& announcement);

/// The run's excitation report (report/excitation_report.hpp): its tables as tables_of() makes
/// them with apply_health(), each parameter with the signal that excites it
/// (model::ParameterInfo::excited_by).
report::ExcitationReport excitation_of(const std::string& vehicle, const std::string& run,
                                       const std::vector<ingest::ModelEstimate>& estimates,
                                       const ingest::RunHealth& health,
                                       const ingest::RunAnnouncement& announcement);

/// Text (the tables, then the notes) or JSON ({"tables":[...],"notes":[...]}).
std::string render(const EstimateTables& tables, bool json);

}  // namespace dynid::server
