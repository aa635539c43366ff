#pragma once
// What `dynid models` and `dynid effects` print: the models and their candidate effects, with
// what each needs (model/model_needs.hpp), answered on this machine without a server.
//
// models_text(): one block per model: the channels it requires and those it reads when present,
// its required and optional constants, the parameters it identifies. models_markdown(): the same
// as one table, the one docs/PROFILES.md holds (tests/docs compares them). effects_text(): a
// model's candidate effects, each with its physics, the channels it adds and its parameters, and
// the dictionary effects' form. Unknown names throw InputError listing the known ones.
#include <string>

namespace dynid::cli {

std::string models_text(const std::string& model = "");
std::string models_markdown();
std::string effects_text(const std::string& model);

}  // namespace dynid::cli
