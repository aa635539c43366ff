#include "options.hpp"

#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "command_line.hpp"

namespace dynid::benchcoverage {
namespace {

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "%s\nusage: dynid-bench-coverage [--seeds N] [--antithetic] [--manoeuvres longitudinal,lateral,launch]\n"
               "                            [--json FILE] [--noise SCALE] [--simex-draws B] [--profile TOML] [--smoke]\n",
               why.c_str());
  std::exit(2);
}

// Only the three manoeuvres the models are identified on: cruise is the smoke test's exactness run.
std::vector<benchcar::Manoeuvre> manoeuvres_of(const std::string& text) {
  std::vector<benchcar::Manoeuvre> out;
  std::stringstream ss(text);
  for (std::string name; std::getline(ss, name, ',');) {
    if (name == "longitudinal") out.push_back(benchcar::Manoeuvre::kLongitudinal);
    else if (name == "lateral") out.push_back(benchcar::Manoeuvre::kLateral);
    else if (name == "launch") out.push_back(benchcar::Manoeuvre::kLaunch);
    else usage("unknown manoeuvre " + name);
  }
  if (out.empty()) usage("--manoeuvres: none given");
  return out;
}

}  // namespace

Options parse_options(int argc, char** argv) {
  Options o;
  bench::CommandLine args(argc, argv, usage);
  while (args.next()) {
    const std::string& a = args.option();
    if (a == "--seeds") o.seeds = static_cast<int>(args.number(1, 1000));
    else if (a == "--manoeuvres") o.manoeuvres = manoeuvres_of(args.value());
    else if (a == "--noise") o.noise_scale = args.number(0, 10);
    else if (a == "--simex-draws") o.simex_draws = static_cast<int>(args.number(2, 1000));
    else if (a == "--antithetic") o.antithetic = true;
    else if (a == "--json") o.json = args.value();
    else if (a == "--profile") o.profile = args.value();
    else if (a == "--smoke") o.smoke = true;
    else if (a == "--help" || a == "-h") usage("");
    else usage("unknown option " + a);
  }
  return o;
}

}  // namespace dynid::benchcoverage
