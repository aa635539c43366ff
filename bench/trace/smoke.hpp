#pragma once
// The benchmark's ctest smoke check (label bench; not the score): the second car goes through the
// product's data path and gives back its own parameters (a noise-free run exactly, up to the
// central difference's h^2 w^2 / 6; a noisy one within a few percent), and the harness runs two
// families end to end. Prints what it measured; returns the number of failed checks.
#include "scoring.hpp"

namespace dynid::benchtrace {

int run_smoke(const RunSetup& setup);

}  // namespace dynid::benchtrace
