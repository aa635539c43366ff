#pragma once
// The coverage benchmark's ctest check (label bench; no score asserted): two seeds of the lateral
// manoeuvre through the whole harness. It fails when a run errs, a parameter with a truth is
// missing, a value or std is not finite and positive, the HAC fit's value is not the estimate
// table's (the same estimator on the same rows), an error exceeds 5 % (the trace smoke's bound
// for these parameters with the car's noise), the instrumental-variable fit is refused, not
// finite and positive or off by more than 5 %, or the summary is not finite; and when a mirrored
// run (--antithetic) does not carry the negated noise of its seed's run, every channel's, to the
// DBC's rounding. Prints what it measured; returns the number of failed checks.
#include <filesystem>

#include <dynid/car/vehicle_profile.hpp>

namespace dynid::benchcoverage {

int run_smoke(const car::VehicleProfile& profile, const std::filesystem::path& work_dir);

}  // namespace dynid::benchcoverage
