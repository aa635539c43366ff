#include "command_line.hpp"

#include <cstdlib>

namespace dynid::bench {

CommandLine::CommandLine(int argc, char** argv, Usage usage) : argc_(argc), argv_(argv), usage_(usage) {}

bool CommandLine::next() {
  if (i_ + 1 >= argc_) return false;
  option_ = argv_[++i_];
  return true;
}

std::string CommandLine::value() {
  if (i_ + 1 >= argc_) fail(option_ + " needs a value");
  return argv_[++i_];
}

double CommandLine::number(double lo, double hi) {
  const std::string v = value();
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (end == v.c_str() || *end != '\0' || !(x >= lo && x <= hi))
    fail(option_ + ": expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}

void CommandLine::fail(const std::string& why) const {
  usage_(why);
  std::abort();  // usage_ exits; this only tells the compiler
}

}  // namespace dynid::bench
