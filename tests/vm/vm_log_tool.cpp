// vm_log_tool: the host-side helper of socketcan_vm_test.sh, built on the project's candump
// reader and writer.
//
//   vm_log_tool excerpt IN OUT SECONDS IFACE   the first SECONDS of IFACE's frames of a log
//   vm_log_tool generate OUT SECONDS           a synthetic can0 log (when no real log is there)
//   vm_log_tool compare EXPECTED ACTUAL TIMED MAX_DRIFT NOW_WITHIN
//
// compare: ACTUAL (what dynid-socketcan-dump received) must hold the frames of EXPECTED in the
// same order with identical id, format, FD flags, RTR, length and payload; its timestamps must be
// non-decreasing, the first within NOW_WITHIN seconds of this machine's clock (kernel receive
// times are wall-clock times), and for the first TIMED frames (the ones canplayer paced) the time
// since the first frame must match EXPECTED's within MAX_DRIFT seconds. Prints every mismatch
// (at most 20) and a summary; exit 0 only when everything holds.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <dynid/can/candump.hpp>
#include <dynid/error.hpp>

namespace {

using dynid::can::Frame;

std::vector<Frame> read_all(const std::string& path) {
  dynid::can::CandumpReader reader{std::filesystem::path(path), dynid::can::OnError::Stop};
  std::vector<Frame> frames;
  Frame f;
  while (reader.next(f)) frames.push_back(f);
  if (reader.stopped())
    throw dynid::InputError(reader.describe(reader.errors().front()));
  return frames;
}

std::ofstream open_output(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw dynid::InputError("cannot write " + path);
  return out;
}

int excerpt(const std::string& in, const std::string& out_path, double seconds,
            const std::string& iface) {
  std::ofstream out = open_output(out_path);
  dynid::can::CandumpWriter writer(out);
  std::size_t n = 0;
  double start = -1.0;
  for (const Frame& f : read_all(in)) {
    if (f.interface_name() != iface) continue;
    if (start < 0.0) start = f.timestamp;
    if (f.timestamp - start > seconds) break;
    writer.write(f);
    ++n;
  }
  std::cout << n << "\n";
  return n > 0 ? 0 : 1;
}

// Ten ids at 100 Hz each with payloads that change every frame, lengths 0..8, one 29-bit id.
int generate(const std::string& out_path, double seconds) {
  std::ofstream out = open_output(out_path);
  dynid::can::CandumpWriter writer(out);
  Frame f;
  f.set_interface_name("can0");
  const int periods = static_cast<int>(seconds * 100.0);
  std::size_t n = 0;
  for (int k = 0; k < periods; ++k) {
    for (unsigned j = 0; j < 10; ++j) {
      f.timestamp = 1700000000.0 + k * 0.01 + j * 0.0007;
      f.extended = j == 9;
      f.id = f.extended ? 0x18DAF100U + j : 0x100U + 0x40U * j;
      f.length = static_cast<std::uint8_t>(j == 0 ? 0 : std::min(8U, j));
      for (unsigned b = 0; b < f.length; ++b)
        f.data[b] = static_cast<std::uint8_t>((k * 7 + static_cast<int>(j * 31 + b)) & 0xFF);
      writer.write(f);
      ++n;
    }
  }
  std::cout << n << "\n";
  return 0;
}

bool same_frame(const Frame& a, const Frame& b) {
  return a.id == b.id && a.extended == b.extended && a.fd == b.fd && a.rtr == b.rtr &&
         a.fd_flags == b.fd_flags && a.length == b.length &&
         std::equal(a.payload().begin(), a.payload().end(), b.payload().begin());
}

std::string show(const Frame& f) { return dynid::can::format_candump_line(f); }

int compare(const std::string& expected_path, const std::string& actual_path, std::size_t timed,
            double max_drift, double now_within) {
  const std::vector<Frame> expected = read_all(expected_path);
  const std::vector<Frame> actual = read_all(actual_path);
  std::size_t problems = 0;
  auto report = [&](const std::string& what) {
    if (++problems <= 20) std::cout << "MISMATCH " << what << "\n";
  };
  if (expected.size() != actual.size())
    report("frame count: expected " + std::to_string(expected.size()) + ", received " +
           std::to_string(actual.size()));
  const std::size_t n = std::min(expected.size(), actual.size());
  double worst_drift = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!same_frame(expected[i], actual[i]))
      report("frame " + std::to_string(i) + ": expected " + show(expected[i]) + ", received " +
             show(actual[i]));
    if (i > 0 && actual[i].timestamp < actual[i - 1].timestamp)
      report("frame " + std::to_string(i) + ": timestamp goes back from " +
             show(actual[i - 1]) + " to " + show(actual[i]));
    if (i < timed) {
      const double drift = (actual[i].timestamp - actual[0].timestamp) -
                           (expected[i].timestamp - expected[0].timestamp);
      worst_drift = std::max(worst_drift, std::abs(drift));
      if (std::abs(drift) > max_drift)
        report("frame " + std::to_string(i) + ": received " + std::to_string(drift) +
               " s off the log's pacing (bound " + std::to_string(max_drift) + " s)");
    }
  }
  const double now = std::chrono::duration<double>(
                         std::chrono::system_clock::now().time_since_epoch()).count();
  if (n > 0 && !(std::abs(actual[0].timestamp - now) <= now_within))
    report("first timestamp " + std::to_string(actual[0].timestamp) + " is not within " +
           std::to_string(now_within) + " s of now (" + std::to_string(now) + ")");
  std::printf("compared %zu frames (%zu paced): worst pacing drift %.6f s, %zu problems\n", n,
              std::min(n, timed), worst_drift, problems);
  return problems == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> a(argv + 1, argv + argc);
  try {
    if (a.size() == 5 && a[0] == "excerpt") return excerpt(a[1], a[2], std::stod(a[3]), a[4]);
    if (a.size() == 3 && a[0] == "generate") return generate(a[1], std::stod(a[2]));
    if (a.size() == 6 && a[0] == "compare")
      return compare(a[1], a[2], std::stoul(a[3]), std::stod(a[4]), std::stod(a[5]));
  } catch (const std::exception& e) {
    std::cerr << "vm_log_tool: " << e.what() << "\n";
    return 1;
  }
  std::cerr << "usage: vm_log_tool excerpt IN OUT SECONDS IFACE | generate OUT SECONDS |"
               " compare EXPECTED ACTUAL TIMED MAX_DRIFT NOW_WITHIN\n";
  return 2;
}
