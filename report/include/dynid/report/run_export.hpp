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
#include <cstddef>
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

/// The export file's comment, one statement per line: the run, the time base, the models exported
/// and, when any, those left out with why (`left_out`: "model: reason; ...").
std::string export_comment(const std::string& run_name, const std::string& exported,
                           const std::string& left_out);

/// The tables, in order, cut into consecutive parts whose MDF4 files (each with `comment`) are
/// at most `max_bytes` each: an export larger than a reply is sent in parts and joined again by
/// the CLI. Throws InputError naming a table that is larger than `max_bytes` by itself.
std::vector<std::vector<Mdf4Table>> export_parts(std::vector<Mdf4Table> tables,
                                                 std::size_t max_bytes, const std::string& comment);

}  // namespace dynid::report
