#pragma once
// The files of a run: channels.csv (measured), channels_true.csv (true values on the same grid),
// truth.toml (every parameter the models identify, as simulated) and can.log (candump -l).
//
// Contract: CSV = a header "time,<channel>,..." with the names of docs/CHANNELS.md, then one row
// per output sample, values in SI with 17 significant digits (exact round trip). The truth file
// holds the parameters in SI with their unit in the key's comment-free name (see truth_table);
// effects switched off report their parameter as 0. Writers throw InputError when a file cannot
// be written.
#include <filesystem>
#include <string>

#include <toml++/toml.h>

#include "dynid/sim/simulator.hpp"

namespace dynid::sim {

void write_channels_csv(const std::filesystem::path& path, const Run& run, bool true_values);
void write_can_log(const std::filesystem::path& path, const Run& run);
toml::table truth_table(const Run& run);
void write_truth(const std::filesystem::path& path, const Run& run);
// All four files into `directory` (created if needed).
void write_run(const std::filesystem::path& directory, const Run& run);

}  // namespace dynid::sim
