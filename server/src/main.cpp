// dynid-server: see include/dynid/server/server.hpp and options.hpp.
//
// SIGTERM and SIGINT: the handler only writes the signal number to a pipe (async-signal-safe;
// any thread may run it, including threads that libraries such as OpenBLAS start before main,
// so blocking the signals for sigwait would not cover them). A thread reading the pipe asks the
// server to stop: the dispatcher leaves its loop, the workers finish what is queued (every
// acknowledged chunk is already durable), and the process exits 0.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <csignal>
#include <thread>

#include "dynid/server/server.hpp"

namespace {

int stop_pipe[2] = {-1, -1};

extern "C" void on_stop_signal(int signal) {
  const auto byte = static_cast<unsigned char>(signal);
  [[maybe_unused]] const auto written = write(stop_pipe[1], &byte, 1);
}

void install_stop_handlers() {
  if (pipe(stop_pipe) != 0) throw std::runtime_error("pipe() for the signal handler failed");
  struct sigaction action = {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
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
  try {
    install_stop_handlers();
    Server server(*options);
    std::thread([&server] {
      unsigned char signal = 0;
      while (read(stop_pipe[0], &signal, 1) < 0) {
      }
      spdlog::info("signal {}: stopping", static_cast<int>(signal));
      server.stop();
    }).detach();
    server.run();
  } catch (const std::exception& e) {
    spdlog::critical("dynid-server: {}", e.what());
    return 1;
  }
  return 0;
}
