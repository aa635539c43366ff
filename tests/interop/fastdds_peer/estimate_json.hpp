#pragma once
// The JSON of a received dynid/Estimate sample, with the keys and status names of
// `dynid estimates --json` (docs/INTEROP.md, "Estimate"), so a test can set the two side by side.
// A parameter's status is its wire status, refined by its verdict when that is not NO_VERDICT;
// numbers that are not finite become null.
#include <nlohmann/json.hpp>

#include "dynid.h"  // fastddsgen's C++ of idl/dynid.idl

namespace peer {

nlohmann::json estimate_json(const dynid::wire::Estimate& estimate);

}  // namespace peer
