#pragma once
// Reading a benchmark's command line (dynid-bench-trace, dynid-bench-coverage): options one by
// one, an option's value, a number within its range. In the bench car's library because that is
// what the benchmarks share; nothing of the car. A bad argument calls the program's usage(),
// which prints why and exits with status 2.
#include <string>

namespace dynid::bench {

class CommandLine {
 public:
  /// Prints `why` and the usage, then exits (never returns).
  using Usage = void (*)(const std::string& why);
  CommandLine(int argc, char** argv, Usage usage);

  /// Steps to the next argument; false when none is left.
  bool next();
  const std::string& option() const { return option_; }
  /// The option's value: the argument after it.
  std::string value();
  /// The value as a number in [lo, hi].
  double number(double lo, double hi);

 private:
  [[noreturn]] void fail(const std::string& why) const;

  int argc_;
  char** argv_;
  Usage usage_;
  int i_ = 0;
  std::string option_;
};

}  // namespace dynid::bench
