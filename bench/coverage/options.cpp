#include "options.hpp"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace dynid::benchcoverage {
namespace {

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "%s\nusage: dynid-bench-coverage [--seeds N] [--manoeuvres longitudinal,lateral,launch] [--json FILE]\n"
               "                            [--noise SCALE] [--profile TOML] [--smoke]\n",
               why.c_str());
  std::exit(2);
}

int seeds_of(const std::string& text) {
  char* end = nullptr;
  const long n = std::strtol(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0' || n < 1 || n > 1000) usage("--seeds: expected an integer in [1, 1000]");
  return static_cast<int>(n);
}

double noise_of(const std::string& text) {
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(x >= 0.0 && x <= 10.0)) usage("--noise: expected a number in [0, 10]");
  return x;
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
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + " needs a value");
      return argv[++i];
    };
    if (a == "--seeds") o.seeds = seeds_of(value());
    else if (a == "--manoeuvres") o.manoeuvres = manoeuvres_of(value());
    else if (a == "--noise") o.noise_scale = noise_of(value());
    else if (a == "--json") o.json = value();
    else if (a == "--profile") o.profile = value();
    else if (a == "--smoke") o.smoke = true;
    else if (a == "--help" || a == "-h") usage("");
    else usage("unknown option " + a);
  }
  return o;
}

}  // namespace dynid::benchcoverage
