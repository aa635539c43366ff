// Reading an ASAM MDF4 bus log against reading the same frames as candump text (the speed the
// MDF4 reader is held to: at least as fast as candump). The MDF4 file's frames are written as
// candump -l text beside it first; then each round reads the MDF4 file and the candump file
// whole through can::open_log (as dynid-car --replay does), the two sides interleaved so they
// meet the same machine load. Prints each side's median of the rounds and the ratio.
//
//   bench_log_read FILE.MF4 [ROUNDS=3]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "dynid/can/candump.hpp"
#include "dynid/can/log_reader.hpp"

namespace {

struct Read {
  double seconds = 0;
  std::size_t frames = 0;
  std::size_t errors = 0;
};

Read read_whole(const std::filesystem::path& path) {
  const auto start = std::chrono::steady_clock::now();
  auto reader = dynid::can::open_log(path);
  dynid::can::Frame frame;
  Read r;
  while (reader->next(frame)) ++r.frames;
  r.errors = reader->error_count();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_log_read FILE.MF4 [ROUNDS=3]\n");
    return 1;
  }
  const std::filesystem::path mdf4 = argv[1];
  const int rounds = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  const std::filesystem::path candump =
      std::filesystem::temp_directory_path() / "bench_log_read.log";
  {
    auto reader = dynid::can::open_log(mdf4);
    std::ofstream out(candump);
    dynid::can::Frame frame;
    while (reader->next(frame)) out << dynid::can::format_candump_line(frame) << '\n';
  }
  std::vector<double> mdf4_s, candump_s;
  Read a, b;
  for (int i = 0; i < rounds; ++i) {
    a = read_whole(mdf4);
    b = read_whole(candump);
    mdf4_s.push_back(a.seconds);
    candump_s.push_back(b.seconds);
  }
  const double m = median(mdf4_s), c = median(candump_s);
  std::printf("%s: %ju bytes, %zu frames (%zu errors): MDF4 %.1f ms\n", mdf4.filename().c_str(),
              static_cast<std::uintmax_t>(std::filesystem::file_size(mdf4)), a.frames, a.errors,
              m * 1e3);
  std::printf("the same frames as candump: %ju bytes, %zu frames (%zu errors): %.1f ms\n",
              static_cast<std::uintmax_t>(std::filesystem::file_size(candump)), b.frames, b.errors,
              c * 1e3);
  std::printf("medians of %d rounds, interleaved: MDF4 reads %.1f times as fast as candump\n",
              rounds, c / m);
  std::filesystem::remove(candump);
  return a.frames == b.frames && a.errors == 0 && b.errors == 0 ? 0 : 1;
}
