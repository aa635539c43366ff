#pragma once
// Internal: the column functions of the generic dictionary (contract in effects.hpp).
#include <string>
#include <vector>

#include "dynid/model/row_model.hpp"

namespace dynid::model::detail {

RowModel::EffectDefinition dictionary_definition(const std::string& name,
                                                 const std::vector<std::string>& groups);

}  // namespace dynid::model::detail
