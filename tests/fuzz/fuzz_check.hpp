#pragma once
// The fuzz targets' own checks: a property that must hold for every input. A failure prints
// what broke and aborts, which libFuzzer records as a crash (with the input) and which fails a
// corpus replay test; a plain assert would vanish under NDEBUG.
#include <cstdio>
#include <cstdlib>

namespace dynid::fuzz {

inline void expect(bool holds, const char* property) {
  if (holds) return;
  std::fprintf(stderr, "fuzz property violated: %s\n", property);
  std::abort();
}

}  // namespace dynid::fuzz
