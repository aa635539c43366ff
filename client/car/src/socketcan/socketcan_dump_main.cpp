// dynid-socketcan-dump: reads one SocketCAN interface and writes what it receives as a candump
// -l log with the project's writer, so the output compares line by line with canplayer's input.
//
//   dynid-socketcan-dump [--frames N] [--seconds T] [--filter ID[:MASK]]... [--output FILE]
//                        INTERFACE
//
// --filter takes hex as candump writes ids: 8 digits is a 29-bit id, fewer an 11-bit one; MASK
// defaults to every id bit; several filters pass a frame any of them passes.
// Stops after N frames, after T seconds, or on SIGINT/SIGTERM, whichever comes first (without
// --frames and --seconds: only on a signal). Once the socket is bound it prints
// "dynid-socketcan-dump: reading <interface>" on stderr, so a script can start the sender then;
// at the end a summary line with the frame, error-frame and kernel-drop counts.
// Exit status: 0 done, 1 SocketCAN or output error (message on stderr), 2 usage.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include <dynid/can/candump.hpp>
#include <dynid/car/socketcan_source.hpp>

namespace {

using dynid::car::SocketCanSource;

struct Arguments {
  std::string interface_name;
  std::optional<std::uint64_t> frames;
  std::optional<double> seconds;
  std::string output;  // empty: stdout
  dynid::car::SocketCanOptions options;
};

constexpr std::string_view kUsage =
    "usage: dynid-socketcan-dump [--frames N] [--seconds T] [--filter ID[:MASK]]... "
    "[--output FILE] INTERFACE\n";

// The source a signal handler stops; request_stop() is async-signal-safe.
std::atomic<SocketCanSource*> g_source{nullptr};

extern "C" void on_signal(int) {
  if (SocketCanSource* s = g_source.load()) s->request_stop();
}

std::uint32_t parse_hex(const std::string& text) {
  std::size_t used = 0;
  const unsigned long value = std::stoul(text, &used, 16);
  if (used != text.size() || text.empty()) throw std::invalid_argument("not hex: " + text);
  return static_cast<std::uint32_t>(value);
}

// "1F334455:1FFFFFFF" or "123"; the kernel-side range checks are SocketCanSource's.
dynid::car::CanFilter parse_filter(const std::string& text) {
  const std::size_t colon = text.find(':');
  const std::string id = text.substr(0, colon);
  dynid::car::CanFilter f = dynid::car::CanFilter::exact(parse_hex(id), id.size() == 8);
  if (colon != std::string::npos) f.mask = parse_hex(text.substr(colon + 1));
  return f;
}

std::optional<Arguments> parse(int argc, char** argv) {
  Arguments a;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const bool has_value = i + 1 < argc;
    try {
      if (arg == "--frames" && has_value) {
        a.frames = std::stoull(argv[++i]);
      } else if (arg == "--seconds" && has_value) {
        a.seconds = std::stod(argv[++i]);
      } else if (arg == "--filter" && has_value) {
        a.options.filters.push_back(parse_filter(argv[++i]));
      } else if (arg == "--output" && has_value) {
        a.output = argv[++i];
      } else if (!arg.starts_with("-") && a.interface_name.empty()) {
        a.interface_name = arg;
      } else {
        return std::nullopt;
      }
    } catch (const std::exception&) {  // stoull/stod/stoul on a non-number
      return std::nullopt;
    }
  }
  if (a.interface_name.empty() || (a.seconds && !(*a.seconds > 0.0))) return std::nullopt;
  return a;
}

// Copies frames until a limit, a signal or the end of the source; returns the frames written.
std::uint64_t dump(SocketCanSource& source, const Arguments& args, std::ostream& out) {
  using Clock = std::chrono::steady_clock;
  const auto limit = args.seconds ? std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(*args.seconds))
                                  : Clock::duration::max();
  const Clock::time_point start = Clock::now();
  dynid::can::CandumpWriter writer(out);
  dynid::can::Frame frame;
  std::uint64_t written = 0;
  while (!args.frames || written < *args.frames) {
    const auto elapsed = Clock::now() - start;
    if (elapsed >= limit) break;
    // Wake at least every second so the time limit holds without a frame arriving.
    const auto wait = std::min<Clock::duration>(limit - elapsed, std::chrono::seconds{1});
    const auto status =
        source.next(frame, std::chrono::ceil<std::chrono::milliseconds>(wait));
    if (status == dynid::car::NextStatus::End) break;
    if (status == dynid::car::NextStatus::Timeout) continue;
    writer.write(frame);
    ++written;
  }
  return written;
}

int run(const Arguments& args) {
  std::ofstream file;
  if (!args.output.empty()) {
    file.open(args.output);
    if (!file) {
      std::cerr << "dynid-socketcan-dump: cannot write " << args.output << "\n";
      return 1;
    }
  }
  std::ostream& out = args.output.empty() ? std::cout : file;

  SocketCanSource source(args.interface_name, args.options);
  g_source.store(&source);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::cerr << "dynid-socketcan-dump: reading " << args.interface_name << std::endl;

  const std::uint64_t written = dump(source, args, out);
  g_source.store(nullptr);
  out.flush();
  std::cerr << "dynid-socketcan-dump: " << written << " frames, " << source.error_frames()
            << " error frames, " << source.dropped() << " dropped by the kernel\n";
  if (!out) {
    std::cerr << "dynid-socketcan-dump: write error\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Arguments> args = parse(argc, argv);
  if (!args) {
    std::cerr << kUsage;
    return 2;
  }
  try {
    return run(*args);
  } catch (const dynid::InputError& e) {  // SocketCanError included
    std::cerr << "dynid-socketcan-dump: " << e.what() << "\n";
    return 1;
  }
}
