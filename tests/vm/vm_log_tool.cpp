// vm_log_tool: the host-side helper of socketcan_vm_test.sh, built on the project's candump
// reader and writer.
//
//   vm_log_tool excerpt IN OUT SECONDS IFACE   the first SECONDS of IFACE's frames of a log
//   vm_log_tool generate OUT SECONDS           a synthetic can0 log (when no real log is there)
//   vm_log_tool compare EXPECTED ACTUAL TIMED MAX_DRIFT NOW_WITHIN
//   vm_log_tool chunks LIVE REPLAYED
//   vm_log_tool aux-writer PIPE COPY SECONDS   (in the VM) a logger writing into a named pipe
//
// compare: ACTUAL (what dynid-socketcan-dump received) must hold the frames of EXPECTED in the
// same order with identical id, format, FD flags, RTR, length and payload; its timestamps must be
// non-decreasing, the first within NOW_WITHIN seconds of this machine's clock (kernel receive
// times are wall-clock times), and for the first TIMED frames (the ones canplayer paced) the time
// since the first frame must match EXPECTED's within MAX_DRIFT seconds. Prints every mismatch
// (at most 20) and a summary; exit 0 only when everything holds.
//
// chunks: two chunk files (dynid-car --chunks-out) must hold the same chunks: same count, and per
// chunk the same ids, sequence, first sample index, dimensions, samples (bit for bit), validity
// flags and checksum. Prints the first differences (at most 20) and the figures compared.
//
// aux-writer: an auxiliary logger for dynid-car's live --source (auxiliary_follower.hpp): opens
// PIPE for writing (waiting for its reader), then every 10 ms for SECONDS writes a row
// "t,ax,ay,az" with t the wall clock (the live bus's clock; 6 decimals) and ax = sin(t), to PIPE
// and, line by line, to COPY (the file the host replays beside the dump). Ends on its own, or
// when the reader has gone (the write fails).
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cerrno>
#include <stdexcept>
#include <thread>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <dynid/can/candump.hpp>
#include <dynid/car/chunk_file.hpp>
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

int compare_chunks(const std::string& live_path, const std::string& replayed_path) {
  const auto live = dynid::car::read_chunk_file(live_path);
  const auto replayed = dynid::car::read_chunk_file(replayed_path);
  std::size_t problems = 0;
  auto report = [&](const std::string& what) {
    if (++problems <= 20) std::cout << "MISMATCH " << what << "\n";
  };
  if (live.size() != replayed.size())
    report("chunk count: live " + std::to_string(live.size()) + ", replayed " + std::to_string(replayed.size()));
  const std::size_t n = std::min(live.size(), replayed.size());
  long long rows = 0, valid = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = live[i];
    const auto& b = replayed[i];
    const std::string at = "chunk " + std::to_string(i) + ": ";
    if (a.vehicle != b.vehicle || a.run != b.run) report(at + "vehicle/run differ");
    if (a.sequence != b.sequence || a.sequence != i)
      report(at + "sequence live " + std::to_string(a.sequence) + ", replayed " + std::to_string(b.sequence));
    if (a.first_sample_index != b.first_sample_index)
      report(at + "first sample index live " + std::to_string(a.first_sample_index) + ", replayed " +
             std::to_string(b.first_sample_index));
    if (a.samples.rows() != b.samples.rows() || a.samples.cols() != b.samples.cols()) {
      report(at + "dimensions live " + std::to_string(a.samples.rows()) + "x" + std::to_string(a.samples.cols()) +
             ", replayed " + std::to_string(b.samples.rows()) + "x" + std::to_string(b.samples.cols()));
      continue;
    }
    for (Eigen::Index r = 0; r < a.samples.rows(); ++r)
      for (Eigen::Index c = 0; c < a.samples.cols(); ++c)
        if (std::memcmp(&a.samples(r, c), &b.samples(r, c), sizeof(double)) != 0)
          report(at + "row " + std::to_string(r) + " column " + std::to_string(c) + ": live " +
                 std::to_string(a.samples(r, c)) + ", replayed " + std::to_string(b.samples(r, c)));
    if (a.valid != b.valid) report(at + "validity flags differ");
    if (a.checksum != b.checksum) report(at + "checksum differs");
    rows += a.samples.rows();
    valid += std::count(a.valid.begin(), a.valid.end(), std::uint8_t{1});
  }
  std::printf("compared %zu chunks (sequences 0..%zu), %lld rows (%lld valid) x %lld channels: %zu problems\n",
              n, n == 0 ? 0 : n - 1, rows, valid,
              n == 0 ? 0LL : static_cast<long long>(live.front().samples.cols()), problems);
  return problems == 0 && n > 0 ? 0 : 1;
}

int aux_writer(const std::string& pipe, const std::string& copy_path, double seconds) {
  std::signal(SIGPIPE, SIG_IGN);  // a reader gone is the end, not a signal
  const int out = ::open(pipe.c_str(), O_WRONLY | O_CLOEXEC);
  if (out < 0) throw std::runtime_error(pipe + ": " + std::strerror(errno));
  std::FILE* copy = std::fopen(copy_path.c_str(), "w");
  if (copy == nullptr) throw std::runtime_error(copy_path + ": " + std::strerror(errno));
  const std::string header = "t,ax,ay,az\n";
  std::fputs(header.c_str(), copy);
  std::fflush(copy);
  if (::write(out, header.data(), header.size()) < 0) return 1;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  std::uint64_t rows = 0;
  while (std::chrono::steady_clock::now() < end) {
    const double t = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    char line[96];
    const int n = std::snprintf(line, sizeof line, "%.6f,%.6f,0,9.81\n", t, std::sin(t));
    std::fputs(line, copy);
    std::fflush(copy);
    if (::write(out, line, static_cast<std::size_t>(n)) != n) break;
    ++rows;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::fclose(copy);
  ::close(out);
  std::cerr << "vm_log_tool aux-writer: " << rows << " rows\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> a(argv + 1, argv + argc);
  try {
    if (a.size() == 5 && a[0] == "excerpt") return excerpt(a[1], a[2], std::stod(a[3]), a[4]);
    if (a.size() == 3 && a[0] == "generate") return generate(a[1], std::stod(a[2]));
    if (a.size() == 6 && a[0] == "compare")
      return compare(a[1], a[2], std::stoul(a[3]), std::stod(a[4]), std::stod(a[5]));
    if (a.size() == 3 && a[0] == "chunks") return compare_chunks(a[1], a[2]);
    if (a.size() == 4 && a[0] == "aux-writer") return aux_writer(a[1], a[2], std::stod(a[3]));
  } catch (const std::exception& e) {
    std::cerr << "vm_log_tool: " << e.what() << "\n";
    return 1;
  }
  std::cerr << "usage: vm_log_tool excerpt IN OUT SECONDS IFACE | generate OUT SECONDS |"
               " compare EXPECTED ACTUAL TIMED MAX_DRIFT NOW_WITHIN | chunks LIVE REPLAYED |"
               " aux-writer PIPE COPY SECONDS\n";
  return 2;
}
