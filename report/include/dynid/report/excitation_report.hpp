#pragma once
// The excitation report of one run (issue 16 item 4): for every model, which parameters this run
// identifies and which it cannot; for those, the signal that must move and the manoeuvre that
// moves it (model::ParameterInfo::excited_by, e.g. "vx over a wide range (coast down from high
// speed)"); then, over the run, each such manoeuvre with every parameter it would bring, so an
// engineer plans the next run from one list.
//
// Statuses are the estimate table's (model/parameter_status.hpp): identified; poorly identified
// (more of the same excitation helps, so it is listed under its manoeuvre too); not excited;
// implausible (outside the model's physical bounds: a model error or a missing effect, not
// something a manoeuvre cures, so it points to `dynid residual` instead); and the base-parameter
// analysis' regrouped, dependent and eliminated (structural: the model cannot separate them on
// any run of this kind). A model that has no estimate (not run, no row yet) is listed with why.
//
// format_excitation_text(): for people. excitation_json(): every field, for tools.
#include <string>
#include <vector>

#include "dynid/dds/estimate_table.hpp"

namespace dynid::report {

struct ModelExcitation {
  dds::EstimateTable table;             ///< the run's estimate table of the model
  std::vector<std::string> excited_by;  ///< per table parameter, in its order ("" when none declared)
};

struct ExcitationReport {
  std::string vehicle;
  std::string run;
  std::vector<ModelExcitation> models;
  std::vector<std::string> notes;  ///< "<model>: <why there is no estimate>"
};

/// One manoeuvre (an `excited_by` text) and the parameters ("model.parameter") it would bring.
struct ManoeuvreNeed {
  std::string excited_by;
  std::vector<std::string> not_excited;
  std::vector<std::string> poorly_identified;
};

/// The manoeuvres that would identify what the run cannot, in the order the models name them.
std::vector<ManoeuvreNeed> manoeuvre_needs(const ExcitationReport& report);

std::string format_excitation_text(const ExcitationReport& report);
std::string excitation_json(const ExcitationReport& report);

}  // namespace dynid::report
