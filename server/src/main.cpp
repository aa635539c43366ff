// dynid-server: see include/dynid/server/server.hpp and options.hpp.
//
// SIGTERM and SIGINT are blocked in every thread and taken by one thread with sigwait, which
// asks the server to stop: the dispatcher leaves its loop, the workers finish what is queued
// (every acknowledged chunk is already durable), and the process exits 0.
#include <spdlog/spdlog.h>

#include <csignal>
#include <cstdlib>
#include <thread>

#include "dynid/server/server.hpp"

namespace {

sigset_t stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  return set;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace dynid::server;
  std::optional<ServerOptions> options;
  try {
    options = parse_options(argc, argv);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  if (!options) return 0;  // --help
  spdlog::set_level(spdlog::level::from_str(options->log_level));
  spdlog::flush_on(spdlog::level::info);  // the log is a file under systemd and in tests
  const sigset_t signals = stop_signals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);  // before any thread starts: all inherit it
  try {
    Server server(*options);
    std::thread([&server, signals] {
      int signal = 0;
      sigwait(&signals, &signal);
      spdlog::info("signal {}: stopping", signal);
      server.stop();
    }).detach();
    server.run();
  } catch (const std::exception& e) {
    spdlog::critical("dynid-server: {}", e.what());
    return 1;
  }
  return 0;
}
