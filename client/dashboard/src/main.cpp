// dynid-dashboard: the fleet and its estimates in a browser, live. A DDS subscriber like the CLI:
// it reads every vehicle's Estimate topic (transient-local, so a new dashboard shows the latest
// estimates at once), asks the servers for the fleet's vehicles and runs every --poll seconds
// and a run's channel health on demand, and serves a page, its JSON and a server-sent-event
// stream over HTTP (http_routes.hpp). It reads only; it lets in only who holds the token.
//
// Exit codes: 0 stopped by SIGINT or SIGTERM, 1 the HTTP address could not be bound, 2 bad
// command line, token or DDS configuration, 7 no DDS participant index was free.
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <thread>

#include <dynid/options/option_checks.hpp>

#include "dynid/cli/request_client.hpp"
#include "dynid/dashboard/fleet_state.hpp"
#include "dynid/dashboard/http_routes.hpp"
#include "dynid/dashboard/page.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/dds/topics.hpp"
#include "dynid/error.hpp"

// After Eigen (through the headers above): glibc's <resolv.h>, which httplib.h includes, defines
// a macro `_res`, a parameter name in Eigen's headers.
#include <httplib.h>

namespace {

using namespace std::chrono_literals;
using dynid::dashboard::FleetState;
using nlohmann::json;

// A token guessed in a lifetime of tries is no credential: 16 characters at least (the
// deployment makes 32 random hex digits: docs/DASHBOARD.md).
constexpr std::size_t kMinTokenLength = 16;
// Connections served at once: two per open page (its event stream and a request), with room.
constexpr std::size_t kConnections = 64;

struct Options {
  std::string listen = "127.0.0.1:8087";
  std::string token_file;
  std::string config;
  dds_domainid_t domain = 0;
  double poll_s = 5.0;
  double timeout_s = 10.0;
  std::size_t history = 1000;
};

std::string read_token(const Options& o) {
  std::string token;
  if (!o.token_file.empty()) {
    std::ifstream in(o.token_file);
    if (!in) throw dynid::InputError("--token-file " + o.token_file + ": cannot be read");
    std::getline(in, token);
  } else if (const char* env = std::getenv("DYNID_DASHBOARD_TOKEN")) {
    token = env;
  }
  while (!token.empty() && (token.back() == '\r' || token.back() == ' ')) token.pop_back();
  if (token.size() < kMinTokenLength)
    throw dynid::InputError(
        "the dashboard's token (--token-file or $DYNID_DASHBOARD_TOKEN) must have at least " +
        std::to_string(kMinTokenLength) + " characters; it has " + std::to_string(token.size()));
  return token;
}

// The servers' requests, one at a time (RequestClient numbers its requests; it is not shared).
class Servers {
 public:
  Servers(const dynid::dds::Participant& participant, std::chrono::milliseconds timeout)
      : client_(participant, dynid::cli::default_client_id()), timeout_(timeout) {}

  // [{"vehicle": V, "runs": [...]}] of every server, or throws NoServer.
  std::string fleet() {
    const std::lock_guard lock(mutex_);
    const auto replies = client_.call_all("vehicles", {{"format", "json"}}, timeout_);
    json out = json::array();
    for (const std::string& v : dynid::cli::merged_vehicles(replies)) {
      // A vehicle whose server does not answer is listed without its runs, the others with.
      json runs;
      try {
        const dynid::dds::Reply r =
            client_.call("runs", {{"vehicle", v}, {"format", "json"}}, timeout_);
        if (r.status == dynid::dds::ReplyStatus::kOk) runs = json::parse(r.payload, nullptr, false);
      } catch (const dynid::cli::NoServer&) {
      }
      out.push_back({{"vehicle", v}, {"runs", runs.is_discarded() ? json() : runs}});
    }
    return out.dump();
  }

  // The `estimate` reply of a run (every model, channel health, notes), at most one request per
  // run every 2 s: a page open on many screens does not multiply the server's work.
  dynid::dashboard::RunReply run(const std::string& vehicle, const std::string& run) {
    const std::lock_guard lock(mutex_);
    const auto key = vehicle + "\n" + run;
    const auto now = std::chrono::steady_clock::now();
    if (const auto c = cache_.find(key); c != cache_.end() && now - c->second.first < 2s)
      return c->second.second;
    dynid::dashboard::RunReply out;
    try {
      std::vector<dynid::dds::RequestArgument> arguments{{"vehicle", vehicle}, {"format", "json"}};
      if (!run.empty()) arguments.push_back({"run", run});
      const dynid::dds::Reply r = client_.call("estimate", arguments, timeout_);
      using S = dynid::dds::ReplyStatus;
      out.status = r.status == S::kOk           ? 200
                   : r.status == S::kNotFound   ? 404
                   : r.status == S::kBadRequest ? 400
                                                : 502;
      out.body = r.status == S::kOk ? r.payload : json({{"error", r.error}}).dump();
    } catch (const dynid::cli::NoServer& e) {
      out = {504, json({{"error", e.what()}}).dump()};
    } catch (const dynid::cli::Interrupted& e) {  // the dashboard is stopping
      return {503, json({{"error", e.what()}}).dump()};
    }
    cache_[key] = {now, out};
    return out;
  }

 private:
  std::mutex mutex_;
  dynid::cli::RequestClient client_;
  std::chrono::milliseconds timeout_;
  std::map<std::string,
           std::pair<std::chrono::steady_clock::time_point, dynid::dashboard::RunReply>>
      cache_;
};

void read_estimates(const dynid::dds::Participant& participant, FleetState& state,
                    const std::atomic<bool>& stop) {
  dynid::dds::Reader<dynid_wire_Estimate> reader(participant, {dynid::dds::kAllVehiclesPartition});
  while (!stop) {
    for (auto& sample : reader.wait_take(200ms)) {
      try {
        state.add(dynid::dds::from_wire(sample.data));
      } catch (const std::exception& e) {  // one malformed sample is dropped, said, not fatal
        std::cerr << "dynid-dashboard: estimate dropped: " << e.what() << "\n";
      }
    }
  }
}

void poll_fleet(Servers& servers, FleetState& state, const Options& o,
                const std::atomic<bool>& stop) {
  std::string last = "[]";
  while (!stop) {
    try {
      last = servers.fleet();
      state.set_fleet(last, "");
    } catch (const dynid::cli::NoServer& e) {
      state.set_fleet(
          last,
          std::string("no dynid-server answered (the list is the last one received): ") + e.what());
    } catch (const std::exception& e) {
      state.set_fleet(last, e.what());
    }
    for (auto waited = 0ms;
         !stop && waited < std::chrono::milliseconds(static_cast<long long>(o.poll_s * 1000));
         waited += 100ms)
      std::this_thread::sleep_for(100ms);
  }
}

// Stopping on SIGINT and SIGTERM, whichever thread the signal lands on (a library may have
// started threads before main that do not block it: OpenBLAS's pool, the sanitizers'): the
// handler first calls the request client's own (request_client.hpp: a wait for a server's reply
// ends within a second instead of at its timeout), then writes the signal to a pipe that one
// thread of ours reads (wait_stop). Writing to a pipe is async-signal-safe; nothing else is done
// in the handler.
int g_stop_pipe[2] = {-1, -1};
struct sigaction g_client_action = {};

void request_stop(int signal) {
  const char byte = static_cast<char>(signal);
  [[maybe_unused]] const ssize_t written = write(g_stop_pipe[1], &byte, 1);
}

extern "C" void dashboard_stop_signal(int signal) {
  const int saved = errno;
  if (g_client_action.sa_handler != SIG_DFL && g_client_action.sa_handler != SIG_IGN)
    g_client_action.sa_handler(signal);
  request_stop(signal);
  errno = saved;
}

void install_stop_handler() {
  dynid::cli::stop_on_signals();
  sigaction(SIGTERM, nullptr, &g_client_action);
  if (pipe2(g_stop_pipe, O_CLOEXEC) != 0)
    throw std::runtime_error("pipe2: " + std::string(std::strerror(errno)));
  struct sigaction action = {};
  action.sa_handler = dashboard_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

// The signal that asked to stop, 0 for a stop of our own.
int wait_stop() {
  char byte = 0;
  while (read(g_stop_pipe[0], &byte, 1) < 0 && errno == EINTR) {
  }
  return byte;
}

std::pair<std::string, int> host_port(const std::string& listen) {
  const std::size_t colon = listen.rfind(':');
  if (colon == std::string::npos)
    throw dynid::InputError("--listen " + listen + ": expected HOST:PORT");
  try {
    const int port = std::stoi(listen.substr(colon + 1));
    if (port < 0 || port > 65535) throw std::out_of_range("port");
    return {listen.substr(0, colon), port};
  } catch (const std::logic_error&) {
    throw dynid::InputError("--listen " + listen + ": the port must be 0..65535");
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const char* env = std::getenv("DYNID_CYCLONE_CONFIG")) o.config = env;
  CLI::App app{"dynid-dashboard: the fleet and its estimates, live, in a browser (reads only)"};
  app.add_option("--listen", o.listen,
                 "HOST:PORT to serve on (default 127.0.0.1:8087; port 0: any free one)");
  app.add_option(
      "--token-file", o.token_file,
      "file whose first line is the token a browser must give (or $DYNID_DASHBOARD_TOKEN); "
      "at least 16 characters");
  app.add_option("--cyclone-config", o.config,
                 "Cyclone DDS configuration: file, file:// URI or XML (or $DYNID_CYCLONE_CONFIG)");
  app.add_option("--domain", o.domain, "DDS domain id")->check(dynid::input::within(0, 230));
  app.add_option("--poll", o.poll_s,
                 "seconds between two listings of the fleet's vehicles and runs")
      ->check(dynid::input::within(0.2, 3600.0));
  app.add_option("--timeout", o.timeout_s, "seconds to wait for a server's reply")
      ->check(dynid::input::within(0.1, 600.0));
  app.add_option("--history", o.history,
                 "points kept per model's plots (thinned by half when full)")
      ->check(dynid::input::within(4, 100000));
  CLI11_PARSE(app, argc, argv);

  std::string token;
  std::pair<std::string, int> address;
  try {
    token = read_token(o);
    address = host_port(o.listen);
  } catch (const dynid::InputError& e) {
    std::cerr << "dynid-dashboard: " << e.what() << "\n";
    return 2;
  }
  install_stop_handler();

  std::unique_ptr<dynid::dds::Participant> participant;
  std::unique_ptr<Servers> servers;
  try {
    dynid::dds::ParticipantOptions po{o.domain, dynid::dds::config_uri(o.config)};
    po.index_wait = 20s;
    participant = std::make_unique<dynid::dds::Participant>(po);
    servers = std::make_unique<Servers>(
        *participant, std::chrono::milliseconds(static_cast<long long>(o.timeout_s * 1000)));
  } catch (const dynid::dds::NoParticipantIndex& e) {
    std::cerr << "dynid-dashboard: " << e.what() << "\n";
    return 7;
  } catch (const std::exception& e) {  // a configuration Cyclone refuses, a missing file
    std::cerr << "dynid-dashboard: cannot join DDS domain " << o.domain
              << " with the Cyclone configuration '" << o.config.substr(0, 200)
              << "' (--cyclone-config or $DYNID_CYCLONE_CONFIG): " << e.what() << "\n";
    return 2;
  }
  FleetState state(o.history);
  httplib::Server http;
  // A connection holds one of the pool's threads while it is open, and each browser keeps its
  // event stream open: the library's default of 8 would let the eighth screen starve the others.
  http.new_task_queue = [] { return new httplib::ThreadPool(kConnections); };
  dynid::dashboard::install_routes(
      http, state, token, dynid::dashboard::page(),
      [&servers](const std::string& v, const std::string& r) { return servers->run(v, r); });
  const int port = address.second == 0
                       ? http.bind_to_any_port(address.first)
                       : (http.bind_to_port(address.first, address.second) ? address.second : -1);
  if (port < 0) {
    std::cerr << "dynid-dashboard: cannot listen on " << o.listen << "\n";
    return 1;
  }
  std::atomic<bool> stop{false};
  std::thread reader([&] { read_estimates(*participant, state, stop); });
  std::thread poller([&] { poll_fleet(*servers, state, o, stop); });
  std::thread stopper([&] {
    const int signal = wait_stop();
    std::cout << "dynid-dashboard: "
              << (signal > 0 ? "signal " + std::to_string(signal) : "the server ended")
              << ": stopping" << std::endl;
    stop = true;
    state.close();
    http.stop();
  });
  std::cout << "dynid-dashboard: listening on http://" << address.first << ":" << port
            << "/ (open /login?token=... once)" << std::endl;
  http.listen_after_bind();
  if (!stop) request_stop(0);  // the HTTP server ended on its own
  stopper.join();
  reader.join();
  poller.join();
  return 0;
}
