#pragma once
// A run's export (`dynid export`, the `export` request): what engineers take on into asammdf,
// CANape or MATLAB. Per model and equation group, one table on the rows the model is fitted on
// (the run's decimation grid where the model's masks keep a row: residual/model_fit.hpp):
//   - the preprocessed channels the model read (filtered, derivatives d_<name> as the model
//     took them: ingest/recorded_run.hpp), each in its catalogue unit;
//   - "<model>.<group>.measured": the measured side y, in the group's unit (Model::group_unit);
//   - "<model>.<group>.fitted": W x at least squares' solution on the whole run (DYCARO's
//     weighted estimate, the one the residual loop judges), and
//   - "<model>.<group>.residual": y - W x.
// The table's comment names the effects declared and the parameters' values with their standard
// deviations, so that the file says which model its fitted values are.
#include <string>
#include <vector>

#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/model.hpp"
#include "dynid/report/mdf4_writer.hpp"

namespace dynid::report {

/// The tables of `model` with `effects` on the preprocessed run, one per equation group that has
/// rows, named "<model>.<group>". Throws InputError as residual::fit_model does (a channel missing,
/// an unknown effect, no row).
std::vector<Mdf4Table> export_tables(const model::Model& model,
                                     const std::vector<std::string>& effects,
                                     const std::vector<ingest::PreprocessedSegment>& segments,
                                     double sample_rate_hz, int odmf);

}  // namespace dynid::report
